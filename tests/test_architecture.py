"""Import contracts between the packages, read from the source (function-level imports included).

- `nanoimpact` (the shared leaf) imports none of `continuum`, `md`, `calibration`, not even lazily;
- `continuum` and `md` never import each other, and neither imports `calibration`;
- inside md, the engine (`md.engine`) never imports a workflow (`md.workflows`) or the recipe (`md.recipe`);
- inside continuum, only the model's factory (`continuum.model.factory`) imports a concrete contact law
  (a module of `continuum.laws` that defines a `ContactLaw` subclass); the laws and the model read summit
  surfaces through their declared protocol (`continuum.rough.surface.SummitSurface`), never by `getattr`;
- calibration reaches continuum only through its public face (`continuum`, `continuum.api`);
- no module of the project imports another in a circle (function-level imports included);
- no library module switches matplotlib's backend (`matplotlib.use`) or draws through pyplot.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("nanoimpact", "continuum", "md", "calibration")
FORBIDDEN = {
    "nanoimpact": {"continuum", "md", "calibration"},
    "continuum": {"md", "calibration"},
    "md": {"continuum", "calibration"},
    "calibration": set(),
}


def _modules(package: str) -> list[Path]:
    return sorted(p for p in (ROOT / package).rglob("*.py") if "__pycache__" not in p.parts)


def _imported_tops(path: Path) -> set[tuple[str, int]]:
    """Top-level package names imported anywhere in the module (relative imports resolve to its own)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update((alias.name.split(".")[0], node.lineno) for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add((node.module.split(".")[0], node.lineno))
    return found


@pytest.mark.parametrize("package", PACKAGES)
def test_package_imports_respect_the_layer_contracts(package):
    bad = [f"{path.relative_to(ROOT)}:{line} imports {top}"
           for path in _modules(package) for top, line in _imported_tops(path) if top in FORBIDDEN[package]]
    assert not bad, "\n".join(bad)


def test_the_contract_scan_sees_function_level_imports(tmp_path):
    """The scan must catch a lazy import inside a function (the way cycles used to hide)."""
    module = tmp_path / "m.py"
    module.write_text("def f():\n    from md.runner import run_hash\n    import calibration.cli\n")
    assert {top for top, _ in _imported_tops(module)} == {"md", "calibration"}


@pytest.mark.parametrize("package", PACKAGES)
def test_library_code_never_switches_the_matplotlib_backend(package):
    bad = []
    for path in _modules(package):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "use" \
                    and isinstance(node.func.value, ast.Name) and node.func.value.id == "matplotlib":
                bad.append(f"{path.relative_to(ROOT)}:{node.lineno} matplotlib.use(...)")
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
                if any(n == "matplotlib.pyplot" for n in names) or (
                        isinstance(node, ast.ImportFrom) and node.module == "matplotlib"
                        and any(a.name == "pyplot" for a in node.names)):
                    bad.append(f"{path.relative_to(ROOT)}:{node.lineno} imports pyplot (use matplotlib.figure.Figure)")
    assert not bad, "\n".join(bad)


# ------------------------------------------------------------------------------------------ module graph

def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _all_modules() -> dict[str, Path]:
    return {_module_name(p): p for package in PACKAGES for p in _modules(package)}


def _imported_modules(path: Path, known: set[str], name: str | None = None) -> set[tuple[str, int]]:
    """Project modules a module imports anywhere (function level included): ``from a import b`` counts as
    ``a.b`` when that is a module, else ``a``; relative imports are resolved (`name`: the module's dotted name, read
    from its path by default)."""
    name = name or _module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            found.update((a.name, node.lineno) for a in node.names if a.name in known)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            for a in node.names:
                full = f"{module}.{a.name}"
                if full in known:
                    found.add((full, node.lineno))
                elif module in known:
                    found.add((module, node.lineno))
    # a module's own ancestor packages are loaded before it whatever it imports: a name taken from one of them
    # (``from . import __version__``) is no edge of the graph
    ancestors = {".".join(name.split(".")[:k]) for k in range(1, name.count(".") + 1)}
    return {(m, line) for m, line in found if m != name and m not in ancestors}


def _graph() -> dict[str, set[str]]:
    modules = _all_modules()
    known = set(modules)
    return {m: {t for t, _ in _imported_modules(p, known)} for m, p in modules.items()}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan), each sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_module_imports_another_in_a_circle():
    cycles = _cycles(_graph())
    assert not cycles, "import cycles (function-level imports included):\n" + "\n".join(" <-> ".join(c) for c in cycles)


def test_the_cycle_scan_sees_a_lazy_cycle():
    """Two modules that import each other, one of them inside a function."""
    assert _cycles({"md.a": {"md.b"}, "md.b": {"md.a"}, "md.c": {"md.a"}}) == [["md.a", "md.b"]]
    assert _cycles({"md.a": {"md.b"}, "md.b": set()}) == []


def test_the_md_engine_never_imports_a_workflow_or_the_recipe():
    modules = _all_modules()
    known = set(modules)
    bad = [f"{p.relative_to(ROOT)}:{line} imports {m}"
           for name, p in modules.items() if name == "md.engine" or name.startswith("md.engine.")
           for m, line in _imported_modules(p, known)
           if m in ("md.recipe", "md.workflows") or m.startswith(("md.workflows.", "md.recipe."))]
    assert not bad, "\n".join(bad)


# ------------------------------------------------------------------------------------------ public faces

#: The modules of continuum another package may import: the package itself (its lazy front door) and its api.
CONTINUUM_FACES = {"continuum", "continuum.api"}


def _continuum_imports_below_the_face(source: str, label: str, known: set[str]) -> list[str]:
    """`label:line imports m` for every continuum module the module's `source` imports (function level included)
    other than the public faces."""
    bad = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            # `from continuum import model` imports the module continuum.model; `from continuum.api import x` a name
            names = [f"{node.module}.{a.name}" if f"{node.module}.{a.name}" in known else node.module
                     for a in node.names]
        else:
            continue
        bad += [f"{label}:{node.lineno} imports {n}" for n in names
                if (n == "continuum" or n.startswith("continuum.")) and n not in CONTINUUM_FACES]
    return bad


def test_calibration_imports_continuum_only_through_its_public_face():
    known = set(_all_modules())
    bad = [hit for path in _modules("calibration")
           for hit in _continuum_imports_below_the_face(path.read_text(), str(path.relative_to(ROOT)), known)]
    assert not bad, "\n".join(bad)


def test_the_face_scan_sees_a_deep_import_even_inside_a_function():
    source = ("from continuum.api import run_scene\nimport continuum\nfrom continuum import api\n\n\ndef f():\n"
              "    from continuum.dynamics.impact import run_impact\n    from continuum import model\n"
              "    import continuum.scene\n")
    assert sorted(_continuum_imports_below_the_face(source, "m.py", set(_all_modules()))) == [
        "m.py:7 imports continuum.dynamics.impact", "m.py:8 imports continuum.model", "m.py:9 imports continuum.scene"]


# ------------------------------------------------------------------------------------------ continuum laws

FACTORY = "continuum.model.factory"


def _declares_abstract_methods(node: ast.ClassDef) -> bool:
    """A class that declares `abstractmethod`s is scaffolding for laws (ContactLaw, RoughRollerBase), not a law."""
    names = {d.id if isinstance(d, ast.Name) else d.attr
             for f in node.body if isinstance(f, ast.FunctionDef)
             for d in f.decorator_list if isinstance(d, (ast.Name, ast.Attribute))}
    return "abstractmethod" in names


def _concrete_law_modules() -> set[str]:
    """Modules of `continuum.laws` that define a concrete ContactLaw subclass (directly or through another law
    or an abstract base)."""
    classes: dict[str, tuple[str, set[str], bool]] = {}
    for path in _modules("continuum"):
        name = _module_name(path)
        if name.startswith("continuum.laws."):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.ClassDef):
                    bases = {b.id if isinstance(b, ast.Name) else b.attr for b in node.bases
                             if isinstance(b, (ast.Name, ast.Attribute))}
                    classes[node.name] = (name, bases, _declares_abstract_methods(node))
    laws, grown = {"ContactLaw"}, True
    while grown:
        new = {c for c, (_, bases, _) in classes.items() if bases & laws} - laws
        laws |= new
        grown = bool(new)
    return {classes[c][0] for c in laws if c in classes and not classes[c][2]}


def test_inside_continuum_only_the_model_factory_imports_concrete_laws():
    modules = _all_modules()
    known = set(modules)
    concrete = _concrete_law_modules()
    assert {"continuum.laws.hertz", "continuum.laws.jkr", "continuum.laws.rough_roller", "continuum.laws.rough_rigid",
            "continuum.laws.discrete_roller", "continuum.laws.wet"} <= concrete
    assert "continuum.laws.base" not in concrete and "continuum.laws.roller_base" not in concrete
    bad = [f"{p.relative_to(ROOT)}:{line} imports {m}"
           for name, p in modules.items()
           if name.startswith("continuum.") and name != FACTORY and not name.startswith("continuum.laws.")
           for m, line in _imported_modules(p, known) if m in concrete]
    assert not bad, "\n".join(bad)


def test_the_law_scan_sees_the_factorys_function_level_imports():
    """The factory imports every concrete law inside its functions: the scan must see them all."""
    modules = _all_modules()
    seen = {m for m, _ in _imported_modules(modules[FACTORY], set(modules))}
    assert _concrete_law_modules() <= seen


@pytest.mark.parametrize("package", ["continuum/laws", "continuum/model"])
def test_laws_and_model_never_probe_an_object_with_getattr(package):
    bad = [f"{path.relative_to(ROOT)}:{node.lineno} {node.func.id}(...)"
           for path in sorted((ROOT / package).rglob("*.py"))
           for node in ast.walk(ast.parse(path.read_text()))
           if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in ("getattr", "hasattr")]
    assert not bad, "\n".join(bad)


def test_both_summit_surfaces_satisfy_the_declared_protocol():
    from continuum.rough.branch_laws import make_summit_law
    from continuum.rough.gw import GWJKRSurface
    from continuum.rough.gw_branches import GWBranchSurface
    from continuum.rough.summits import SummitStatistics
    from continuum.rough.surface import SummitSurface

    stats = SummitStatistics(3e-9, 1e13, 0.2e-6)
    tabulated = GWJKRSurface(stats, 0.0, 10e9, z_max=4.0, resolution="fast")
    generic = GWBranchSurface(stats, make_summit_law("dmt", 0.2e-6, 0.12, 10e9, z0=0.3e-9, delta_max=1e-7), z_max=4.0)
    for surface in (tabulated, generic):
        assert isinstance(surface, SummitSurface)
    assert (tabulated.kind, generic.kind) == ("tabulated", "generic")


# ------------------------------------------------------------------------------------------ layer order
#: Inside continuum and md, the layers from the bottom up; a module belongs to the layer of the longest prefix that
#: names it. A module imports only from its own layer or below, at module level and inside functions alike (a lazy
#: import is no licence to reach up: pass a callable in, or move the code down).
LAYERS = {
    "continuum": (
        # closed forms and their kernels, the input schema and the parameter origins
        ("continuum.physics", "continuum.reference", "continuum.schema", "continuum.origins"),
        # the half-space, the menisci, the result's proportions; compiled bridge sums import nothing of the project
        ("continuum.elastic", "continuum.wet", "continuum.output.proportions", "continuum.laws.bridge_kernel"),
        ("continuum.rough",),                                  # summit statistics, GW tables, topographies
        ("continuum.scene", "continuum.numerics"),             # the resolved scene; the compiled contact phase
        ("continuum.laws",),                                   # contact laws
        ("continuum.model",),                                  # which law a scene gets, regimes, estimates
        ("continuum.output",),                                 # results, notices, figures, provenance
        ("continuum.dynamics",),                               # the driver, one impact, ensembles, maps
        ("continuum.paper",),                                  # the paper's cases and claims
        ("continuum.api", "continuum.cli", "continuum"),       # the public face
    ),
    "md": (
        ("md.units", "md.lammps_loader"),
        ("md.system",),
        ("md.build", "md.analysis"),
        ("md.engine", "md.recipe"),
        ("md.workflows",),
        ("md.report_tables",),
        ("md.cli", "md.doctor", "md"),
    ),
}


def _layer(module: str, layers: tuple[tuple[str, ...], ...]) -> int | None:
    """Index of the layer whose longest prefix names `module` (None: not in these layers)."""
    best = (-1, None)
    for i, prefixes in enumerate(layers):
        for p in prefixes:
            if (module == p or module.startswith(p + ".")) and len(p) > best[0]:
                best = (len(p), i)
    return best[1]


def _function_level_lines(path: Path) -> set[int]:
    """Lines of the import statements that sit inside a function body."""
    lines = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            lines.update(n.lineno for n in ast.walk(node) if isinstance(n, (ast.Import, ast.ImportFrom)))
    return lines


def _upward_imports(modules: dict[str, Path], layers: tuple[tuple[str, ...], ...]) -> list[str]:
    known = set(modules)
    bad = []
    for name, path in sorted(modules.items()):
        own = _layer(name, layers)
        if own is None:
            continue
        lazy = _function_level_lines(path)
        for target, line in sorted(_imported_modules(path, known, name)):
            up = _layer(target, layers)
            if up is not None and up > own:
                where = "inside a function" if line in lazy else "at module level"
                bad.append(f"{name}:{line} imports {target} {where} (layer {own} -> {up})")
    return bad


@pytest.mark.parametrize("package", sorted(LAYERS))
def test_no_import_goes_up_a_layer_not_even_inside_a_function(package):
    modules = {m: p for m, p in _all_modules().items() if m == package or m.startswith(package + ".")}
    assert all(_layer(m, LAYERS[package]) is not None for m in modules), \
        [m for m in modules if _layer(m, LAYERS[package]) is None]
    bad = _upward_imports(modules, LAYERS[package])
    assert not bad, "\n".join(bad)


def test_the_layer_scan_sees_an_upward_import_inside_a_function(tmp_path):
    """Negative control: a reference module that imports the driver inside a function is caught; the same import
    from the driver down to the reference, or across one layer, is not."""
    low = tmp_path / "low.py"
    low.write_text("import math\n\n\ndef f():\n    from continuum.dynamics import driver\n    return driver\n")
    high = tmp_path / "high.py"
    high.write_text("def g():\n    from continuum.reference import jkr\n    return jkr\n")
    modules = {"continuum.reference.low": low, "continuum.dynamics.driver": high, "continuum.reference.jkr": high}
    layers = LAYERS["continuum"]
    assert _layer("continuum.reference.low", layers) < _layer("continuum.dynamics.driver", layers)
    assert _layer("continuum.laws.bridge_kernel", layers) < _layer("continuum.laws.jkr", layers)
    bad = _upward_imports(modules, layers)
    assert len(bad) == 1 and "imports continuum.dynamics.driver inside a function" in bad[0], bad
