"""House rules a reader relies on, checked over the whole library (text and syntax trees; the dotted-name rule
imports the names it checks).

* Functions stay readable: none in `continuum/`, `md/`, `calibration/` or `nanoimpact/` is over 100 lines.
* History lives in git, not in the code: no "issue N" or "session N" narrative in library code.
* Every cited repository path exists: the docs, the README, the inputs' READMEs and the code name files as
  ``docs/model.md``, ``tests/continuum/test_paper.py`` or ``md/system/forcefield.py`` (prefixed by a top-level folder,
  or relative to `inputs/`, the shipped data root), and markdown links point at files next to the page. Paths
  outside the repository (``shared/...``) are not something a reader of the repository can open, so citing one
  fails too. ``NAME``-style placeholders are templates, not citations.
* Every dotted name a text cites resolves: ``md.engine.hashing.run_hash`` in the docs, the README, the inputs'
  READMEs or a docstring or comment of the code (benchmarks and tests included) imports as a module and its
  attributes, so a renamed or removed name cannot linger in the prose (names under a class are its attributes,
  fields or instance attributes set in its methods; a trailing file suffix such as ``md.md`` is a file name).
* No citation of a review or notes document outside the repository (``md-review-2``), and no version narrative
  in library code ("before version 2", "version 3 of the protocol added ..."): how a protocol came to be belongs
  in git history; a workflow's ``version`` says only what it is now.
* One import path per name: no module lists in ``__all__`` a name it only imports, marks an import as kept for
  re-export (``noqa: F401``), or is nothing but imports, and no comment or docstring keeps an "old name" alive.
  A package's front doors, its ``__init__`` and its ``api`` module (docs/api.md), gather its public names.

Each rule has a negative control on a synthetic source, so a scanner that found nothing would fail.
"""
from __future__ import annotations

import ast
import importlib
import inspect
import io
import re
import textwrap
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIBRARY = ("continuum", "md", "calibration", "nanoimpact")
MAX_FUNCTION_LINES = 100
TOP = ("docs", "tests", "md", "continuum", "calibration", "nanoimpact", "inputs", "benchmarks", ".ci", "shared")
EXTENSIONS = ("md", "py", "toml", "json", "txt", "csv", "yaml", "yml", "cfg", "sh")
CITED = re.compile(r"(?<![\w./-])((?:\.\./)*(?:" + "|".join(re.escape(t) for t in TOP) + r")/[\w./-]*\w\.(?:"
                   + "|".join(EXTENSIONS) + r"))(?![\w/])")
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")
PLACEHOLDER = re.compile(r"(?:^|/)[A-Z][A-Z_]{2,}\.")
HISTORY = re.compile(r"\b(?:issues?|sessions?)\s+#?\d+", re.IGNORECASE)
COMPAT = re.compile(r"old names?\b.*\b(?:still work|kept|alive)|for (?:backward[s]? )?compatibility|"
                    r"backward[s]?[- ]compatib|noqa: ?F401", re.IGNORECASE)
FRONT_DOORS = ("__init__.py", "api.py")
#: A dotted name rooted in one of the packages (not part of a path or of a longer dotted name).
DOTTED = re.compile(r"(?<![\w/.-])((?:" + "|".join(LIBRARY) + r")(?:\.[A-Za-z_]\w*)+)")
#: Last parts that make a dotted name a file name (``md.md``, ``calibration.json``), not a Python name.
FILE_SUFFIXES = set(EXTENSIONS) | {"png", "pdf", "npz", "lock", "log"}
#: A review or notes document cited by name (they live outside the repository).
OUTSIDE_DOCUMENT = re.compile(r"\b[\w-]*review-\d+\b", re.IGNORECASE)
#: A version narrative: what an earlier version of a protocol did, what a version changed, or the number a
#: workflow's ``version`` holds typed beside it (it goes stale at the next change).
VERSION_HISTORY = re.compile(
    r"\b(?:before|after|since|until|prior to|as of|up to)\s+(?:the\s+)?(?:[\w-]+\s+)?(?:protocol\s+)?version\s+\d+"
    r"|\bversions?\s+\d+\s+(?:of the protocol\s+)?(?:added|changed|removed|replaced|introduced|fixed|moved|was|had|"
    r"used|gave)\b|\(version\s+\d+\)|``version``\s*\(\d+\)", re.IGNORECASE)


def library_files():
    for package in LIBRARY:
        yield from sorted((ROOT / package).rglob("*.py"))


def doc_sources():
    for pattern in ("*.md", "docs/**/*.md", "inputs/**/*.md", "benchmarks/**/*.py", "tests/**/*.py", ".ci/*"):
        yield from sorted(p for p in ROOT.glob(pattern) if p.is_file())
    yield from library_files()


# ----------------------------------------------------------------------------- the scanners
def long_functions(source: str, name: str, limit: int = MAX_FUNCTION_LINES) -> list[str]:
    """`name:line function (n lines)` for every function or method of `source` longer than `limit` lines."""
    return [f"{name}:{node.lineno} {node.name} ({node.end_lineno - node.lineno + 1} lines)"
            for node in ast.walk(ast.parse(source))
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
            and node.end_lineno - node.lineno + 1 > limit]


def history_lines(source: str, name: str) -> list[str]:
    return [f"{name}:{n}: {line.strip()}" for n, line in enumerate(source.splitlines(), 1) if HISTORY.search(line)]


def _exists(ref: str, page: Path) -> bool:
    if ref.startswith("../"):
        return (page.parent / ref).resolve().is_relative_to(ROOT) and (page.parent / ref).exists()
    if ref.startswith("shared/"):
        return False
    return (ROOT / ref).exists() or (ROOT / "inputs" / ref).exists()


def missing_citations(text: str, page: Path) -> list[str]:
    """Cited paths in `text` (the contents of `page`) that do not exist in the repository."""
    bad = []
    for n, line in enumerate(text.splitlines(), 1):
        refs = [m.group(1) for m in CITED.finditer(line)]
        bad += [f"{n}: {r}" for r in refs if not PLACEHOLDER.search(r) and not _exists(r, page)]
        if page.suffix == ".md":
            for m in LINK.finditer(line):
                target = m.group(1)
                if re.match(r"[a-z]+:", target) or target.startswith(("/", "<")):
                    continue
                if not (page.parent / target).exists():
                    bad.append(f"{n}: link {target}")
    return bad


def prose(source: str, name: str) -> list[tuple[int, str]]:
    """(first line, text) of each block a reader reads as prose: a Python module's docstrings and comments, else
    each line of the file."""
    if not name.endswith(".py"):
        return list(enumerate(source.splitlines(), 1))
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body \
                and isinstance(node.body[0], ast.Expr) and isinstance(node.body[0].value, ast.Constant) \
                and isinstance(node.body[0].value.value, str):
            out.append((node.body[0].lineno, node.body[0].value.value))
    out += [(tok.start[0], tok.string) for tok in tokenize.generate_tokens(io.StringIO(source).readline)
            if tok.type == tokenize.COMMENT]
    return sorted(out)


def _hits(pattern: re.Pattern, blocks: list[tuple[int, str]]) -> list[tuple[int, str]]:
    """(line, match) of every match of ``pattern`` in the prose blocks (a match may span lines of a block)."""
    return [(start + text[:m.start()].count("\n"), m.group(0)) for start, text in blocks
            for m in pattern.finditer(text)]


def _members(cls: type) -> set[str]:
    """A class's declared attributes: its fields and annotations and every ``self.NAME`` its methods assign."""
    names = set(getattr(cls, "__dataclass_fields__", {})) | set(getattr(cls, "__annotations__", {}))
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    except (OSError, TypeError, SyntaxError):
        return names
    return names | {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute) and isinstance(n.ctx, ast.Store)}


def resolves(dotted: str) -> bool:
    """Whether ``dotted`` imports: its longest module prefix imports and the rest are attributes (for a class, also
    its declared instance attributes)."""
    parts = dotted.split(".")
    if parts[-1] in FILE_SUFFIXES:
        return True
    obj, k = None, len(parts)
    while k > 0:
        try:
            obj = importlib.import_module(".".join(parts[:k]))
            break
        except ImportError:
            k -= 1
    if obj is None:
        return False
    for part in parts[k:]:
        try:
            obj = getattr(obj, part)
        except AttributeError:
            return isinstance(obj, type) and part in _members(obj)
    return True


def unresolved_names(source: str, name: str) -> list[str]:
    """`name:line: dotted` for every dotted package name in the prose of `source` that does not resolve."""
    return [f"{name}:{n}: {hit}" for n, hit in _hits(DOTTED, prose(source, name)) if not resolves(hit)]


def narrative_lines(source: str, name: str) -> list[str]:
    """`name:line: words` for every citation of a review document by name and every version narrative in the
    prose of `source`."""
    blocks = prose(source, name)
    return [f"{name}:{n}: {' '.join(hit.split())}"
            for n, hit in sorted(_hits(OUTSIDE_DOCUMENT, blocks) + _hits(VERSION_HISTORY, blocks))]


def compatibility_reexports(source: str, name: str) -> list[str]:
    """Names a non-package module lists in __all__ without defining them; a module of imports only; comments or
    docstrings that keep old names alive."""
    bad = [f"{name}:{n}: {line.strip()}" for n, line in enumerate(source.splitlines(), 1) if COMPAT.search(line)]
    if name.endswith(FRONT_DOORS):
        return bad
    tree = ast.parse(source)
    defined, imported, exported = set(), set(), []
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            defined.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for t in targets:
                for leaf in ast.walk(t):
                    if isinstance(leaf, ast.Name):
                        defined.add(leaf.id)
                        if leaf.id == "__all__" and isinstance(node.value, (ast.List, ast.Tuple)):
                            exported = [e.value for e in node.value.elts if isinstance(e, ast.Constant)]
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            imported |= {(a.asname or a.name).split(".")[0] for a in node.names}
    bad += [f"{name}: __all__ re-exports {e}" for e in exported if e in imported and e not in defined]
    body = [n for n in tree.body if not (isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant))]
    if body and all(isinstance(n, (ast.Import, ast.ImportFrom)) or
                    (isinstance(n, ast.Assign) and [getattr(t, "id", "") for t in n.targets] == ["__all__"])
                    for n in body) and any(isinstance(n, ast.ImportFrom) and n.module != "__future__" for n in body):
        bad.append(f"{name}: a module of imports only")
    return bad


# ----------------------------------------------------------------------------- the rules
def test_no_library_function_is_over_100_lines():
    bad = [hit for path in library_files()
           for hit in long_functions(path.read_text(), str(path.relative_to(ROOT)))]
    assert not bad, "\n".join(bad)


def test_no_issue_or_session_narrative_in_library_code():
    bad = [hit for path in library_files() for hit in history_lines(path.read_text(), str(path.relative_to(ROOT)))]
    assert not bad, "\n".join(bad)


def test_every_cited_repository_path_exists():
    bad = [f"{page.relative_to(ROOT)}:{hit}" for page in doc_sources()
           for hit in missing_citations(page.read_text(errors="replace"), page)]
    assert not bad, "\n".join(bad)


def test_every_cited_dotted_name_resolves():
    bad = [hit for page in doc_sources()
           for hit in unresolved_names(page.read_text(errors="replace"), str(page.relative_to(ROOT)))]
    assert not bad, "\n".join(bad)


def test_no_review_citation_or_version_narrative_in_library_code():
    bad = [hit for path in library_files() for hit in narrative_lines(path.read_text(), str(path.relative_to(ROOT)))]
    assert not bad, "\n".join(bad)


def test_no_module_re_exports_a_name_for_compatibility():
    bad = [hit for path in library_files()
           for hit in compatibility_reexports(path.read_text(), str(path.relative_to(ROOT)))]
    assert not bad, "\n".join(bad)


# ----------------------------------------------------------------------------- negative controls
def test_the_scanners_find_what_they_look_for():
    long_source = "def f():\n" + "    x = 1\n" * MAX_FUNCTION_LINES + "def g():\n    return 1\n"
    assert long_functions(long_source, "m.py") == [f"m.py:1 f ({MAX_FUNCTION_LINES + 1} lines)"]
    assert history_lines('"""Bounded cost (issue 12)."""\nx = 1  # per Issue #3\ny = 2\n', "m.py") == [
        'm.py:1: """Bounded cost (issue 12)."""', "m.py:2: x = 1  # per Issue #3"]
    page = ROOT / "docs" / "page.md"
    nowhere, outside = "tests" + "/test_nowhere.py", "shared" + "/docs/notes.md"     # not citations of this file
    text = (f"See `docs/model.md` and {nowhere}, `inputs/params/NAME.toml`, `md/adhesion_silica.toml`,\n"
            f"[model](model.md), [gone](gone.md), [site](https://example.org) and `{outside}`.\n")
    assert missing_citations(text, page) == [f"1: {nowhere}", f"2: {outside}", "2: link gone.md"]
    shim = ('"""The old name of `pkg.model`: its names, re-exported; the old names here still work."""\n'
            "from .model import select_law\n__all__ = ['select_law']\n")
    assert compatibility_reexports(shim, "pkg/models.py") == [
        'pkg/models.py:1: """The old name of `pkg.model`: its names, re-exported; the old names here still work."""',
        "pkg/models.py: __all__ re-exports select_law", "pkg/models.py: a module of imports only"]
    marked = "from .impl import helper  # noqa" + ": F401  (re-exported)\n\n\ndef f():\n    return 1\n"
    assert compatibility_reexports(marked, "pkg/m.py") == ["pkg/m.py:1: " + marked.splitlines()[0]]
    clean = "from .costs import LIMIT\n\n\ndef law():\n    return LIMIT\n\n\n__all__ = ['law']\n"
    assert compatibility_reexports(clean, "pkg/law.py") == []
    doc = ("See `md.engine.hashing.run_hash`, continuum.dynamics.driver._contact and `calibration.executors`;\n"
           "the `md.engine.plan.Job` fields (`md.engine.plan.Job.canonical`), docs/md.md and md.md.\n")
    assert unresolved_names(doc, "page.md") == ["page.md:1: continuum.dynamics.driver._contact",
                                                "page.md:1: calibration.executors"]
    code = '"""Uses `md.nowhere`."""\nimport md\nx = md.read_text()  # md.gone\n'
    assert unresolved_names(code, "m.py") == ["m.py:1: md.nowhere", "m.py:3: md.gone"]
    story = ('"""The plan (md-review-2 F8); before\nversion 3 the chains were 20x too short.\n\n'
             'Version 4 added the lift; ``version`` (4) is the protocol now."""\n')
    assert narrative_lines(story, "m.py") == ["m.py:1: before version 3", "m.py:1: md-review-2",
                                              "m.py:4: Version 4 added", "m.py:4: ``version`` (4)"]
