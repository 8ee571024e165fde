"""Import contracts between the packages, read from the source (function-level imports included).

- `nanoimpact` (the shared leaf) imports none of `continuum`, `md`, `calibration`, not even lazily;
- `continuum` and `md` never import each other, and neither imports `calibration`;
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
