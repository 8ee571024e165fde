"""md's public face: calibration imports md only through the package root (``from md import ...``), and every
name the root offers resolves to the object its module defines."""
from __future__ import annotations

import ast
import importlib
from pathlib import Path

import md

ROOT = Path(__file__).resolve().parents[2]


def deep_md_imports(source: str, name: str) -> list[str]:
    """`name:line: module` for every import of a module below md's root (``import md.recipe``, ``from
    md.engine.store import ...``) in `source`, function-level imports included."""
    bad = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            bad += [f"{name}:{node.lineno}: {a.name}" for a in node.names if a.name.startswith("md.")]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").startswith("md."):
            bad.append(f"{name}:{node.lineno}: {node.module}")
    return bad


def test_calibration_imports_md_only_through_its_root():
    bad = [hit for path in sorted((ROOT / "calibration").rglob("*.py"))
           for hit in deep_md_imports(path.read_text(), str(path.relative_to(ROOT)))]
    assert not bad, "\n".join(bad)


def test_the_scan_sees_deep_imports_at_any_level():
    source = ("from md import run_recipe\n\n"
              "def f():\n    from md.engine.store import run_dir_for\n    import md.recipe\n")
    assert deep_md_imports(source, "m.py") == ["m.py:4: md.engine.store", "m.py:5: md.recipe"]


def test_every_public_name_is_its_modules_own_object():
    for name in md.__all__:
        module = importlib.import_module(md._PUBLIC[name])
        assert getattr(md, name) is getattr(module, name), name
