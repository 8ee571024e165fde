"""One input engine: a `Field` declares a key once (type, unit, range, default, doc), and that declaration
drives the value check, the one-line error, the docs tables, the JSON Schema for editors and the frozen
dataclasses the loaders return (`frozen_dataclass`).

Scene keys (`continuum.schema`), MD recipe keys (`md.recipe`) and calibration recipe keys
(`calibration.pipeline`) are all `Field`s or subclasses that add what their files need (angles in degrees
for scenes; the section and workflows of a recipe key). Leaf module: imports none of continuum, md,
calibration.

A check returns the value in file units (integers widened to float for real-valued keys) or raises the
caller's `InputError` subclass naming the key, the value and what is allowed, e.g.
``body.radius = -1: must be a number >= 1e-09 and <= 1 m``.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Sequence

from .errors import InputError

__all__ = ["REQUIRED", "Field", "Resolved", "resolved", "section_members", "frozen_dataclass", "markdown_table",
           "json_schema"]

JSON_SCHEMA_DIALECT = "https://json-schema.org/draft/2020-12/schema"


class _Required:
    """The default of a key that must be given (a sentinel that survives copying and prints well)."""

    def __repr__(self) -> str:
        return "REQUIRED"

    def __copy__(self):
        return self

    def __deepcopy__(self, memo):
        return self


REQUIRED: Any = _Required()


@dataclass(frozen=True)
class Field:
    """One input key.

    `key`: the name (dotted for nested tables); `kind`: float, int, str, bool or list (then `item` is the
    element kind, `length` the allowed lengths, if restricted, and `empty_ok` admits []); `low`/`high` bound numbers,
    `low_open`/`high_open` make a bound strict; `choices` lists allowed strings. `default` is REQUIRED (must be given),
    None (optional: absent means "not given") or a value.
    """

    key: str
    kind: type
    unit: str
    doc: str
    default: Any = REQUIRED
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple[str, ...] = ()
    item: type | None = None
    length: tuple[int, ...] = ()
    empty_ok: bool = False

    # ------------------------------------------------------------------ description
    def _item_field(self) -> "Field":
        return Field(self.key, self.item or float, self.unit, "", low=self.low, high=self.high,
                     low_open=self.low_open, high_open=self.high_open, choices=self.choices)

    def allowed(self) -> str:
        """What the key accepts, in words (the end of every error message about it)."""
        if self.kind is list:
            n = " or ".join(str(k) for k in self.length) if self.length else ("any number of" if self.empty_ok
                                                                               else "one or more")
            return f"a list of {n} items, each {self._item_field().allowed()}"
        if self.kind is str:
            return "one of " + ", ".join(repr(c) for c in self.choices) if self.choices else "a string"
        if self.kind is bool:
            return "true or false"
        name = "an integer" if self.kind is int else "a number"
        parts = []
        if self.low is not None:
            parts.append(f"{'>' if self.low_open else '>='} {self.low:g}")
        if self.high is not None:
            parts.append(f"{'<' if self.high_open else '<='} {self.high:g}")
        unit = f" {self.unit}" if self.unit and self.unit != "1" else ""
        return (f"{name} " + " and ".join(parts) + unit) if parts else f"{name}{unit}"

    def type_name(self) -> str:
        return f"list of {(self.item or float).__name__}" if self.kind is list else self.kind.__name__

    def default_text(self) -> str:
        """The default as the docs tables show it."""
        if self.default is REQUIRED:
            return "required"
        if self.default is None:
            return "not set"
        return f"`{self.default!r}`"

    # ------------------------------------------------------------------ checking
    def check(self, value: Any, origin: str = "", *, error: type[InputError] = InputError,
              name: str | None = None) -> Any:
        """`value` (file units) if this key accepts it, else `error(name, value, "must be ...", origin)`.
        `name` is the key as the file spells it (default `key`; list items are named `name[k]`)."""
        name = self.key if name is None else name
        if self.kind is list:
            if not isinstance(value, list) or (not value and not self.empty_ok) \
                    or (self.length and len(value) not in self.length):
                raise error(name, value, f"must be {self.allowed()}", origin)
            item = self._item_field()
            return [item.check(v, origin, error=error, name=f"{name}[{k}]") for k, v in enumerate(value)]
        if self.kind is str:
            if not isinstance(value, str) or (self.choices and value not in self.choices):
                raise error(name, value, f"must be {self.allowed()}", origin)
            return value
        if self.kind is bool:
            if not isinstance(value, bool):
                raise error(name, value, "must be true or false", origin)
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or (self.kind is int and not isinstance(value, int)):
            raise error(name, value, f"must be {self.allowed()}", origin)
        if not math.isfinite(value):
            raise error(name, value, f"must be finite: {self.allowed()}", origin)
        if self.low is not None and (value < self.low or (self.low_open and value == self.low)):
            raise error(name, value, f"must be {self.allowed()}", origin)
        if self.high is not None and (value > self.high or (self.high_open and value == self.high)):
            raise error(name, value, f"must be {self.allowed()}", origin)
        return float(value) if self.kind is float else int(value)

    # ------------------------------------------------------------------ JSON Schema
    def json_schema(self) -> dict:
        """This key as a JSON Schema (draft 2020-12) property: type, bounds, choices, default, doc and unit."""
        if self.kind is list:
            out: dict = {"type": "array", "items": self._item_field().json_schema(),
                         "minItems": 0 if self.empty_ok else 1}
            if self.length:
                out["minItems"], out["maxItems"] = min(self.length), max(self.length)
        elif self.kind is str:
            out = {"type": "string"}
            if self.choices:
                out["enum"] = list(self.choices)
        elif self.kind is bool:
            out = {"type": "boolean"}
        else:
            out = {"type": "integer" if self.kind is int else "number"}
            if self.low is not None:
                out["exclusiveMinimum" if self.low_open else "minimum"] = self.low
            if self.high is not None:
                out["exclusiveMaximum" if self.high_open else "maximum"] = self.high
        if self.doc:
            unit = f" [{self.unit}]" if self.unit and self.unit != "1" else ""
            out["description"] = f"{self.doc}{unit}"
        if self.default is not REQUIRED and self.default is not None:
            out["default"] = list(self.default) if isinstance(self.default, tuple) else self.default
        return out


# ---------------------------------------------------------------------- docs and editors
def markdown_table(fields: Iterable[Field], columns: Iterable[tuple[str, Callable[[Field], str]]]) -> str:
    """A markdown table with one row per field; `columns` are (header, cell function) pairs."""
    columns = list(columns)
    lines = ["| " + " | ".join(h for h, _ in columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(f) for _, cell in columns) + " |" for f in fields]
    return "\n".join(lines)


def _node(root: dict, path: list[str]) -> dict:
    node = root
    for part in path:
        node = node.setdefault("properties", {}).setdefault(part, {"type": "object", "additionalProperties": False})
    return node


def json_schema(fields: Iterable[tuple[str, Field]], *, title: str, description: str = "",
                required: bool = True) -> dict:
    """A JSON Schema document for a TOML input file: `fields` are (dotted path in the file, Field) pairs;
    dotted paths become nested objects; unknown keys are refused (additionalProperties false), as the
    loaders refuse them. With `required`, a required key is listed in `required` of its table (not for files
    whose required keys may come from elsewhere, as a scene's from its parameter set)."""
    root: dict = {"$schema": JSON_SCHEMA_DIALECT, "title": title, "type": "object", "additionalProperties": False}
    if description:
        root["description"] = description
    for path, f in fields:
        *parents, leaf = path.split(".")
        node = _node(root, parents)
        node.setdefault("properties", {})[leaf] = f.json_schema()
        if f.default is REQUIRED and required:
            node.setdefault("required", [])
            if leaf not in node["required"]:
                node["required"].append(leaf)
    return root


# ---------------------------------------------------------------------- typed values
@dataclass(frozen=True)
class Resolved:
    """An attribute of a generated dataclass that no single key's declaration types: a value the loader resolves
    (a mass from a density and a shape, a tolerance from a preset) or a nested section. `key` names the
    declaration it stands for, if one does (the contract tests check that every key lands somewhere)."""

    annotation: Any
    unit: str
    doc: str
    default: Any = REQUIRED
    key: str | None = None


def resolved(f: Field, doc: str | None = None, unit: str | None = None) -> Resolved:
    """`f` as an attribute that the loader always fills (optional in the file, resolved before the dataclass is
    built: e.g. a tolerance that defaults to the fidelity preset's)."""
    kind = list[f.item or float] if f.kind is list else f.kind
    return Resolved(kind, f.unit if unit is None else unit, f.doc if doc is None else doc, key=f.key)


def section_members(fields: Iterable[Field], section: str, skip: Iterable[str] = ()) -> list[tuple[str, Field]]:
    """(attribute, declaration) for the keys directly in the dotted table `section` ('' for the top level), in
    declaration order, leaving out the names in `skip`: the members of that section's `frozen_dataclass`."""
    skip = set(skip)
    out = []
    for f in fields:
        parent, _, leaf = f.key.rpartition(".")
        if parent == section and leaf not in skip:
            out.append((leaf, f))
    return out


def _attribute(member: Field | Resolved, unit: Callable[[Field], str],
               default: Callable[[Field], Any]) -> tuple[Any, Any, str, str, str | None]:
    """(annotation, default or REQUIRED, unit, doc, key) of one attribute."""
    if isinstance(member, Resolved):
        return member.annotation, member.default, member.unit, member.doc, member.key
    kind: Any = list[member.item or float] if member.kind is list else member.kind
    value = member.default if member.default is REQUIRED else default(member)
    if member.default is None:
        kind = kind | None
    return kind, value, unit(member), member.doc, member.key


def frozen_dataclass(name: str, members: Sequence[tuple[str, Field | Resolved]], *, doc: str, module: str,
                     namespace: dict | None = None, bases: tuple[type, ...] = (),
                     unit: Callable[[Field], str] = lambda f: f.unit,
                     default: Callable[[Field], Any] = lambda f: f.default) -> type:
    """A frozen, keyword-only dataclass with one attribute per (name, declaration) in `members`, in that order:
    typed from the declaration (``float``, ``float | None`` for an optional key, ...), defaulted from it (a
    required key has no default) and documented from it (the class docstring lists each attribute with its unit
    and the key it comes from). So a key is declared once and its dataclass follows. `Resolved` members are
    attributes the loader computes; `namespace` adds properties and methods, `bases` base classes; `unit`/`default`
    map a key's file unit and default to the attribute's (angles: degrees in the file, radians in the dataclass). Each
    dataclass field carries its key, unit and doc in ``metadata``."""
    spec, lines = [], []
    for attr, member in members:
        annotation, value, attr_unit, attr_doc, key = _attribute(member, unit, default)
        meta = {"key": key, "unit": attr_unit, "doc": attr_doc}
        if value is REQUIRED:
            field = dataclasses.field(metadata=meta)
        elif isinstance(value, list):
            field = dataclasses.field(default_factory=lambda v=tuple(value): list(v), metadata=meta)
        else:
            field = dataclasses.field(default=value, metadata=meta)
        spec.append((attr, annotation, field))
        shown = f" [{attr_unit}]" if attr_unit and attr_unit != "1" else ""
        where = f", from ``{key}``" if key else ""
        lines.append(f"    {attr}{shown}{where}: {attr_doc}")
    cls = dataclasses.make_dataclass(name, spec, bases=bases, namespace=dict(namespace or {}), frozen=True,
                                     kw_only=True)
    cls.__module__ = module             # so pickle (process pools, Dask) finds the class where it is defined
    cls.__doc__ = doc.rstrip() + "\n\n    Attributes (generated from the key declarations):\n" + "\n".join(lines) + "\n"
    return cls
