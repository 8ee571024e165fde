"""Where each value of a parameter set comes from: the `[meta.origin]` table, checked when a set is read.

A parameter set (inputs/params/NAME.toml) gives scene keys. Every one of them carries its origin, so that no
input a prediction rests on is silently chosen:

    [meta.origin]
    "surfaces.work_of_adhesion" = { kind = "md", run_hash = "4346...", recipe = "adhesion_silica" }
    "surfaces.body.youngs_modulus" = { kind = "material", source = "Hopcroft et al., J. MEMS 19 (2010) 229" }
    "surfaces.roughness.summit_radius" = { kind = "chosen", reason = "no topography measured; ..." }

The four kinds and the entry each needs (`ORIGIN_KINDS`): `md` (a value measured by an MD run: its run
hash), `topography` (derived from a height map: the file's SHA-256), `material` (a material constant or a
published measurement: its source), `chosen` (a value the set declares as a choice: the reason). Other entries
(a note, the recipe, the value's stderr) are free. A key without an origin, an origin of an unknown kind, a
kind without its entry, or an origin naming a key the set does not give is a one-line error naming the key.
"""
from __future__ import annotations

from typing import Any, Mapping

from nanoimpact.errors import InputError

#: kind -> the entry that kind must carry (a non-empty string).
ORIGIN_KINDS = {"md": "run_hash", "topography": "sha256", "material": "source", "chosen": "reason"}


class OriginError(InputError):
    """A parameter set's [meta.origin] that does not account for a value: names the key."""


def check_origins(meta: Mapping[str, Any] | None, keys, where: str = "") -> dict:
    """The set's origin table, checked against the set's (flattened, dotted) `keys`; raises OriginError.

    `meta` is the set's [meta] table (or None), `where` the file named in the error."""
    origin = (meta or {}).get("origin")
    if origin is None:
        keys = sorted(keys)
        if not keys:
            return {}
        raise OriginError(keys[0], "(no origin)", "every value of a parameter set needs a [meta.origin] entry "
                          f"{{ kind = {' | '.join(repr(k) for k in ORIGIN_KINDS)}, ... }}", where)
    if not isinstance(origin, Mapping):
        raise OriginError("meta.origin", origin, "must be a table: key -> { kind = ..., ... }", where)
    for key in sorted(keys):
        if key not in origin:
            raise OriginError(key, "(no origin)", "has no [meta.origin] entry; give { kind = "
                              f"{' | '.join(repr(k) for k in ORIGIN_KINDS)}, ... }}", where)
    for key, entry in origin.items():
        check_entry(key, entry, where)
        if key not in keys:
            raise OriginError(f"meta.origin.{key}", entry.get("kind"), "names a key the set does not give; "
                              "remove the entry or give the value", where)
    return dict(origin)


def check_entry(key: str, entry: Any, where: str = "") -> None:
    """One origin entry: a table with a known `kind` and the string that kind needs."""
    if not isinstance(entry, Mapping):
        raise OriginError(f"meta.origin.{key}", entry, "must be a table { kind = ..., ... }", where)
    kind = entry.get("kind")
    if kind not in ORIGIN_KINDS:
        raise OriginError(f"meta.origin.{key}.kind", kind, f"allowed: {', '.join(ORIGIN_KINDS)}", where)
    need = ORIGIN_KINDS[kind]
    text = entry.get(need)
    if not isinstance(text, str) or not text.strip():
        raise OriginError(f"meta.origin.{key}.{need}", text, f"kind = '{kind}' needs a non-empty '{need}'", where)


def describe(entry: Mapping[str, Any]) -> str:
    """One line for a report: the kind and what backs it (run hash shortened to 16 characters)."""
    kind = entry["kind"]
    what = str(entry[ORIGIN_KINDS[kind]])
    if kind in ("md", "topography"):
        what = what[:16]
    extra = f" ({entry['note']})" if entry.get("note") else ""
    return f"{kind}: {what}{extra}"
