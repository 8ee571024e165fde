"""JSON Schemas of the three input files, generated from their field declarations (nanoimpact.fields):
scenes and parameter sets (continuum.schema), MD recipes (md.recipe), calibration recipes
(calibration.pipeline). They ship as package data in `inputs/schema/` so an editor can check a file as it is
written, e.g. with taplo or VS Code's Even Better TOML, by a first line such as

    #:schema https://.../inputs/schema/scene.schema.json

The loaders stay the authority (they also check cross-key rules a schema cannot state); the schemas say the
same per-key rules because both come from one declaration. Regenerate after changing a field:

    python -m calibration.schemas            # rewrites inputs/schema/*.schema.json
    python -m calibration.schemas --check    # exit 1 if a committed schema differs from the declarations
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Callable

from nanoimpact.fileio import atomic_write_text

#: file stem -> function returning the schema (imported when called)
SCHEMAS: dict[str, Callable[[], dict]] = {}


def _scene() -> dict:
    from continuum.api import json_schema
    return json_schema()


def _md_recipe() -> dict:
    from md import json_schema
    return json_schema()


def _calibration() -> dict:
    from calibration.pipeline import json_schema
    return json_schema()


SCHEMAS.update({"scene": _scene, "md-recipe": _md_recipe, "calibration": _calibration})
#: Where the schemas are committed (the source tree's inputs/, shipped as nanoimpact.inputs).
FOLDER = Path(__file__).resolve().parents[1] / "inputs" / "schema"


def render(name: str) -> str:
    return json.dumps(SCHEMAS[name](), indent=2, sort_keys=False) + "\n"


def write(folder: Path = FOLDER) -> list[Path]:
    return [atomic_write_text(Path(folder) / f"{name}.schema.json", render(name)) for name in SCHEMAS]


def stale(folder: Path = FOLDER) -> list[str]:
    """Names whose committed schema differs from what the declarations give now."""
    return [n for n in SCHEMAS if not (Path(folder) / f"{n}.schema.json").is_file()
            or (Path(folder) / f"{n}.schema.json").read_text() != render(n)]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m calibration.schemas", description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="exit 1 if a committed schema is stale; write nothing")
    args = p.parse_args(argv)
    if args.check:
        bad = stale()
        for n in bad:
            print(f"stale: inputs/schema/{n}.schema.json (run python -m calibration.schemas)", file=sys.stderr)
        return 1 if bad else 0
    for path in write():
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
