"""Scene files: read, merge with a parameter set, validate at the edge, build frozen dataclasses.

Resolution order for every key: schema default < parameter set (`params = "NAME"` reads
`inputs/params/NAME.toml`, or `--params NAME|FILE` replaces it) < the scene file itself. The
resolved scene records each value and where it came from. Validation rejects unknown keys and
checks every value's type, sign and range; the first problem raises `SceneError` naming the key,
the value and what is allowed. Nothing here writes files.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import tomllib
from dataclasses import asdict, dataclass
from pathlib import Path

from nanoimpact import data
from nanoimpact.errors import DataNotFound, InputError
from nanoimpact.fields import Resolved, frozen_dataclass, resolved, section_members

from .origins import check_origins
from .physics.limiting_pressure import check_sphere_limits, partner_limits
from .reference.hertz import effective_modulus
from .rough.surface_map import map_statistics, statistics_block
from .rough.topography import KEY_FILE, KEY_SYNTH, TopographyError
from .schema import FIDELITY, FIELD_BY_PATH, FIELDS, REQUIRED, Field, is_section, to_internal


class SceneError(InputError):
    """An invalid scene: names the key, the value and what is allowed."""


# ----------------------------------------------------------------------------- dataclasses
# Generated from the key declarations (continuum.schema.FIELDS; nanoimpact.fields.frozen_dataclass): a section's
# dataclass has one attribute per key of its table, typed, defaulted and documented from the declaration (angles
# in radians). `Resolved` attributes are the ones `_build` computes from several keys or a preset. Keys that no
# attribute holds are listed in FOLDED_KEYS with where they go.
def _members(section: str, skip: tuple[str, ...] = ()) -> list[tuple[str, Field]]:
    """(attribute, declaration) for the scene keys directly in `section` ('' for the top level)."""
    return section_members(FIELDS, section, skip)


def _replace_member(members: list, attr: str, member: Field | Resolved) -> list:
    return [(a, member if a == attr else m) for a, m in members]


def _dataclass(name: str, members, doc: str, namespace: dict | None = None) -> type:
    return frozen_dataclass(name, members, doc=doc, module=__name__, namespace=namespace,
                            unit=lambda f: "rad" if f.degrees else f.unit, default=lambda f: to_internal(f, f.default))


#: Declared keys that no dataclass attribute holds, and where their value goes.
FOLDED_KEYS = {
    "params": "ResolvedScene.params_file (the parameter set read)",
    "body.density": "Body.mass (mass from the density and the shape's volume)",
    "surfaces.sam.coverage": "Surfaces.sam (None when 'none')",
    **{f.path: "Roughness.sigma, summit_density and summit_radius (the synthetic map's statistics; "
               "ResolvedScene.surface)" for f in FIELDS if f.path.startswith(f"{KEY_SYNTH}.")},
}

Body = _dataclass("Body", _replace_member(_members("body", skip=("density",)), "mass",
    Resolved(float, "kg", "Body mass: body.mass, or body.density times the shape's volume.", key="body.mass")),
    "The impacting body (SI).")

# one surface's material: the keys of [surfaces.body] (the substrate has the same three, and two of its own that
# Surfaces holds)
Material = _dataclass("Material", [(a, dataclasses.replace(f, doc=f.doc.replace(" of the body", "")))
                                   for a, f in _members("surfaces.body")],
                      "Elastic constants and water contact angle of one surface ([surfaces.body] or "
                      "[surfaces.substrate]).")

Roughness = _dataclass("Roughness", _members("surfaces.roughness"),
                       "Summit statistics of the (composite) rough surface ([surfaces.roughness]).")

SAM = _dataclass("SAM", _replace_member(_members("surfaces.sam", skip=("coverage",)), "work_of_adhesion",
                                        resolved(FIELD_BY_PATH["surfaces.sam.work_of_adhesion"])),
                 "A self-assembled monolayer on both surfaces ([surfaces.sam] with coverage = 'both'); without "
                 "layer_modulus the layer is rigid.")


def _interface_interaction_range(self) -> float:
    """z0 (m) of the contacting pair: the SAM's when both sides carry one and it is given."""
    if self.sam is not None and self.sam.interaction_range is not None:
        return self.sam.interaction_range
    return self.interaction_range


def _contact_angles(self) -> tuple[float | None, float | None]:
    """Water contact angles (rad) of the two contacting faces: the SAM's on both when covered."""
    if self.sam is not None:
        return self.sam.contact_angle, self.sam.contact_angle
    return self.body.contact_angle, self.substrate.contact_angle


def _interface_work_of_adhesion(self) -> float:
    """Work of adhesion (J/m^2) of the contacting pair: the SAM's when both sides carry one."""
    return self.sam.work_of_adhesion if self.sam is not None else self.work_of_adhesion


def _e_star(self) -> float:
    """Effective (contact) modulus E* in Pa, 1/E* = sum (1 - nu^2)/E (Johnson's convention)."""
    return float(effective_modulus(self.body.youngs_modulus, self.body.poisson_ratio,
                                   self.substrate.youngs_modulus, self.substrate.poisson_ratio))


_surface_keys = dict(_members("surfaces"))
Surfaces = _dataclass(
    "Surfaces",
    [("work_of_adhesion", _surface_keys["work_of_adhesion"]),
     ("body", Resolved(Material, "", "The body's material ([surfaces.body]).")),
     ("substrate", Resolved(Material, "", "The substrate's material ([surfaces.substrate]).")),
     ("roughness", Resolved(Roughness | None, "", "Summit statistics; None for smooth contact.", default=None)),
     ("yield_strength", FIELD_BY_PATH["surfaces.substrate.yield_strength"]),
     ("hardness", FIELD_BY_PATH["surfaces.substrate.hardness"]),
     ("sam", Resolved(SAM | None, "", "The monolayer on both surfaces; None without one.", default=None)),
     ("interaction_range", _surface_keys["interaction_range"])],
    "The pair of surfaces: work of adhesion, each side's material, roughness, SAM, and the substrate's yield "
    "strength and hardness for the plasticity warnings.",
    namespace={"interface_interaction_range": property(_interface_interaction_range),
               "contact_angles": property(_contact_angles),
               "interface_work_of_adhesion": property(_interface_work_of_adhesion),
               "e_star": property(_e_star)})

Environment = _dataclass("Environment", _members("environment"), "The surroundings ([environment]).")
Physics = _dataclass("Physics", _members("physics"),
                     "Model choices ([physics]); 'auto' entries are decided per scene (continuum.model).")
Menisci = _dataclass("Menisci", _members("menisci"), "Capillary condensation settings ([menisci]).")
Numerics = _dataclass(
    "Numerics",
    _replace_member(_replace_member(_members("numerics"), "rtol", resolved(
        FIELD_BY_PATH["numerics.rtol"], "Relative tolerance of the contact integrator: numerics.rtol, or the "
        "fidelity preset's (smooth or rough contact).")), "grid_points", resolved(
        FIELD_BY_PATH["numerics.grid_points"], "Rough contact: grid points across the footprint: numerics.grid_points, "
        "or the fidelity preset's.")) + [
        ("table", Resolved(str, "", "GW table resolution of the fidelity preset.", default="standard"))],
    "Numerical settings ([numerics]); rtol and grid_points resolved from the fidelity preset unless given.")

_top = dict(_members(""))
Scene = _dataclass(
    "Scene",
    [("name", resolved(_top["name"], "Scene name (the file name without extension unless given).")),
     ("description", _top["description"]), ("contact", _top["contact"]),
     ("release_height", _top["release_height"]), ("impact_velocity", _top["impact_velocity"]),
     ("body", Resolved(Body, "", "The impacting body.")),
     ("surfaces", Resolved(Surfaces, "", "The pair of surfaces.")),
     ("environment", Resolved(Environment, "", "The surroundings.")),
     ("physics", Resolved(Physics, "", "Model choices.")),
     ("numerics", Resolved(Numerics, "", "Numerical settings.")),
     ("menisci", Resolved(Menisci, "", "Capillary condensation settings.", default=Menisci()))],
    "A validated scene in SI units (angles in radians).")


@dataclass(frozen=True)
class ResolvedScene:
    """A scene together with the file-unit values it was built from and where each came from."""

    scene: Scene
    values: dict
    sources: dict
    scene_file: str | None
    params_file: str | None
    params_meta: dict | None = None
    surface: dict | None = None
    """result.json's `surface` block: a height map's statistics and source, or the plain statistics of a rough
    scene (source kind 'statistics'); None for smooth contact."""

    def to_json(self) -> dict:
        """JSON-ready record: nested values in file units (as written), sources, files, SI dataclass."""
        return {
            "file": self.scene_file,
            "params_file": self.params_file,
            "values": _nest(self.values),
            "sources": self.sources,
            "params_meta": self.params_meta,
            "si": asdict(self.scene),
        }

    @property
    def input_hash(self) -> str:
        """SHA-256 of the canonical resolved values: identical physics inputs give identical hashes."""
        blob = json.dumps(self.values, sort_keys=True, default=repr).encode()
        return hashlib.sha256(blob).hexdigest()


# ----------------------------------------------------------------------------- reading
def read_toml(path: Path, what: str = "scene") -> dict:
    """Parse a TOML file, turning I/O and syntax problems into SceneError."""
    path = Path(path)
    if not path.is_file():
        raise SceneError(what, str(path), "file not found")
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(what, str(path), f"is not valid TOML ({exc})") from None


def flatten(table: dict, origin: str, prefix: str = "", skip: tuple[str, ...] = ()) -> dict:
    """Flatten nested tables to dotted keys, rejecting any key the schema does not know."""
    flat = {}
    for key, value in table.items():
        path = f"{prefix}{key}"
        if path in skip:
            continue
        if isinstance(value, dict):
            if not is_section(path):
                raise SceneError(path, "{...}", _unknown(path), origin)
            flat.update(flatten(value, origin, path + ".", skip))
        elif path in FIELD_BY_PATH:
            flat[path] = value
        else:
            raise SceneError(path, value, _unknown(path), origin)
    return flat


def _unknown(path: str) -> str:
    parent = path.rsplit(".", 1)[0] if "." in path else ""
    known = sorted(f.path.rsplit(".", 1)[-1] for f in FIELDS
                   if (f.path.rsplit(".", 1)[0] if "." in f.path else "") == parent)
    return f"unknown key; keys allowed here: {', '.join(known)}"


def find_params(spec: str, params_dir: Path | None = None) -> Path:
    """A parameter-set name (user data folder, then the shipped sets) or a path to a TOML file."""
    candidate = Path(spec)
    if candidate.suffix == ".toml" or candidate.is_file():
        if not candidate.is_file():
            raise SceneError("params", spec, "parameter file not found")
        return candidate
    if params_dir is None:
        try:
            return data.find("params", spec)
        except DataNotFound:
            raise SceneError("params", spec, "no parameter set of that name; available: "
                                             f"{', '.join(data.names('params')) or 'none'}") from None
    folder = Path(params_dir)
    path = folder / f"{spec}.toml"
    if not path.is_file():
        names = sorted(p.stem for p in folder.glob("*.toml")) if folder.is_dir() else []
        raise SceneError("params", spec, f"no parameter set of that name; available: {', '.join(names) or 'none'}")
    return path


def find_scene(spec: str | Path) -> Path:
    """A scene file: a path, or the name of a shipped (or user-folder) scene (`hertz_roller`)."""
    try:
        return data.find("scenes", spec, key="scene")
    except DataNotFound as exc:
        raise SceneError("scene", str(spec), exc.allowed) from None


# ----------------------------------------------------------------------------- validation
def check_value(f: Field, value, origin: str):
    """Type and range check of one value in file units; returns it (ints widened to float). The check is the
    field's own (nanoimpact.fields.Field.check), raising SceneError."""
    return f.check(value, origin, error=SceneError)


def resolve_scene(scene_file: str | Path | None = None, *, table: dict | None = None,
                  params: str | None = None, params_dir: Path | None = None,
                  overrides: dict | None = None, override_label: str = "override") -> ResolvedScene:
    """Read, merge and validate a scene (from a file or an in-memory table).

    `params` (a name or a path) replaces the scene's own `params` entry, as `--params` does.
    `overrides` ({dotted key: value}, file units) win over everything and are recorded with the
    source `override_label` (sweeps and the paper's cases use them).
    """
    origin = str(scene_file) if scene_file is not None else "<scene>"
    if table is None:
        if scene_file is None:
            raise ValueError("give a scene file or a table")
        scene_file = find_scene(scene_file)
        table = read_toml(Path(scene_file))
    flat_scene = flatten(table, origin)
    for path, value in flat_scene.items():
        check_value(FIELD_BY_PATH[path], value, origin)
    overrides = dict(overrides or {})
    for path, value in overrides.items():
        if path not in FIELD_BY_PATH:
            raise SceneError(path, value, _unknown(path), override_label)
        check_value(FIELD_BY_PATH[path], value, override_label)

    params_spec = params if params is not None else flat_scene.get("params")
    params_file = None
    flat_params: dict = {}
    params_meta = None
    if params_spec is not None:
        params_file = find_params(params_spec, params_dir)
        raw = read_toml(params_file, "params")
        params_meta = raw.get("meta")
        flat_params = flatten(raw, str(params_file), skip=("meta",))
        for forbidden in ("params", "name", "description"):
            if forbidden in flat_params:
                raise SceneError(forbidden, flat_params[forbidden], "cannot be set by a parameter set",
                                 str(params_file))
        for path, value in flat_params.items():
            check_value(FIELD_BY_PATH[path], value, str(params_file))
        check_origins(params_meta, flat_params, str(params_file))
        flat_scene = {**flat_scene, "params": str(params_spec)}

    values, sources = {}, {}
    set_label = f"params:{Path(params_file).stem}" if params_file else None
    for f in FIELDS:
        if f.path in overrides:
            values[f.path], sources[f.path] = overrides[f.path], override_label
        elif f.path in flat_scene:
            values[f.path], sources[f.path] = flat_scene[f.path], "scene"
        elif f.path in flat_params:
            values[f.path], sources[f.path] = flat_params[f.path], set_label
        elif f.default is REQUIRED:
            continue
        else:
            values[f.path], sources[f.path] = f.default, "default"
    if values.get("surfaces.sam.coverage") != "both" and sources.get("surfaces.sam.layer_modulus") == set_label:
        # a parameter set describes its SAM whether or not a scene covers the surfaces with it
        values["surfaces.sam.layer_modulus"], sources["surfaces.sam.layer_modulus"] = None, f"{set_label} (no SAM)"
    if values.get("name") is None:
        values["name"] = Path(scene_file).stem if scene_file is not None else "scene"
        sources["name"] = "file name"
    surface = _surface(values, sources, scene_file, origin)
    scene = _build(values, origin)
    return ResolvedScene(scene, values, sources, str(scene_file) if scene_file else None,
                         str(params_file) if params_file else None, params_meta, surface=surface)


def _surface(values: dict, sources: dict, scene_file, origin: str) -> dict | None:
    """result.json's `surface` block. A height map's statistics replace sigma, summit_density and summit_radius
    in `values` (source 'topography' or 'synthetic'); continuum.rough.surface_map states the precedence."""
    try:
        stats = map_statistics(values, sources, Path(scene_file).parent if scene_file is not None else None)
    except TopographyError as exc:
        raise SceneError(exc.key, exc.value, exc.allowed, origin) from None
    if stats is None:
        return statistics_block(values, sources) if values.get("contact") == "rough" else None
    label = "topography" if values.get(KEY_FILE) is not None else "synthetic"
    for key, value in stats.values.items():
        values[key] = check_value(FIELD_BY_PATH[key], float(value), f"{origin} ({label} map)")
        sources[key] = label
    return stats.block


def _require(values: dict, path: str, origin: str, why: str):
    if values.get(path) is None:
        raise SceneError(path, None, f"is required {why}", origin)
    return values[path]


def _build(v: dict, origin: str) -> Scene:
    """Cross-field checks, then the dataclasses (SI; degrees -> radians): one step per part of the scene."""
    for f in FIELDS:
        if f.default is REQUIRED and f.path not in v:
            raise SceneError(f.path, None, f"is required: {f.allowed()}", origin)
    si = {path: to_internal(FIELD_BY_PATH[path], val) for path, val in v.items()}
    _check_start(si, origin)
    mass, length = _body_mass(si, v, origin)
    roughness = _roughness(si, origin)
    sam = _sam(si, v, origin)
    _check_law(si, sam, origin)
    _check_menisci(si, sam, origin)
    _check_plasticity(si, sam, origin)
    return _assemble(si, mass, length, roughness, sam)


def _check_start(si: dict, origin: str) -> None:
    """How the body starts: exactly one of release height and impact velocity; gravity to fall from a height."""
    if (si["release_height"] is None) == (si["impact_velocity"] is None):
        raise SceneError("release_height", si["release_height"],
                         "give exactly one of release_height and impact_velocity", origin)
    if si["release_height"] is not None and si["environment.gravity"] == 0.0:
        raise SceneError("environment.gravity", 0.0, "must be > 0 when the body is released from a height", origin)


def _body_mass(si: dict, v: dict, origin: str) -> tuple[float, float | None]:
    """(mass in kg, cylinder length in m or None): the mass given, or the density times the shape's volume."""
    shape = si["body.shape"]
    if shape == "cylinder":
        length = _require(si, "body.length", origin, "for a cylinder")
    else:
        if si["body.length"] is not None:
            raise SceneError("body.length", v["body.length"], "is for cylinders only; remove it for a sphere", origin)
        length = None
    if (si["body.mass"] is None) == (si["body.density"] is None):
        raise SceneError("body.mass", si["body.mass"], "give exactly one of body.mass and body.density", origin)
    if si["body.mass"] is not None:
        mass = si["body.mass"]
    elif shape == "sphere":
        mass = 4.0 / 3.0 * math.pi * si["body.radius"] ** 3 * si["body.density"]
    else:
        mass = math.pi * si["body.radius"] ** 2 * length * si["body.density"]
    return mass, length


def _roughness(si: dict, origin: str):
    """The summit statistics of rough contact (a roller only); None for smooth contact."""
    if si["contact"] != "rough":
        return None
    if si["body.shape"] != "cylinder":
        raise SceneError("contact", "rough", "rough contact is modelled for a roller (body.shape = 'cylinder', "
                         "plane-strain line contact) only", origin)
    for key in ("sigma", "summit_density", "summit_radius"):
        _require(si, f"surfaces.roughness.{key}", origin, "for contact = 'rough' (or a height map: "
                 f"{KEY_FILE} or [{KEY_SYNTH}])")
    return Roughness(**_section(Roughness, si, "surfaces.roughness"))


def _sam(si: dict, v: dict, origin: str):
    """The monolayer on both surfaces; None without one (a layer modulus then has nothing to describe)."""
    sam = None
    if si["surfaces.sam.coverage"] == "both":
        _require(si, "surfaces.sam.work_of_adhesion", origin, "when surfaces.sam.coverage = 'both'")
        sam = SAM(**_section(SAM, si, "surfaces.sam"))
        if sam.layer_modulus is not None:
            _require(si, "surfaces.sam.thickness", origin, "when surfaces.sam.layer_modulus is set (the layer's "
                     "compliance is thickness / modulus)")
    elif si["surfaces.sam.layer_modulus"] is not None:
        raise SceneError("surfaces.sam.layer_modulus", v["surfaces.sam.layer_modulus"],
                         "is for a SAM; set surfaces.sam.coverage = 'both' or remove it", origin)
    return sam


def _check_law(si: dict, sam, origin: str) -> None:
    """The adhesion law fits the contact: no 2-D JKR, summit laws for rough contact, adhesion > 0 where used."""
    shape = si["body.shape"]
    adhesion = sam.work_of_adhesion if sam is not None else si["surfaces.work_of_adhesion"]
    law = si["physics.adhesion_law"]
    if law in ("jkr", "dmt", "maugis_dugdale"):
        if shape == "cylinder" and si["contact"] == "smooth":
            raise SceneError("physics.adhesion_law", law,
                             "a smooth cylinder has no adhesive law here (2-D JKR is not implemented); "
                             "use body.shape = 'sphere' or contact = 'rough'", origin)
        if law != "jkr" and si["contact"] == "smooth" and si["physics.detachment"] != "displacement":
            raise SceneError("physics.detachment", si["physics.detachment"], f"a smooth sphere under "
                             f"physics.adhesion_law = '{law}' lets go under displacement control only (its branches "
                             "have no load-controlled release); use 'displacement' or adhesion_law = 'jkr'", origin)
        if adhesion <= 0.0:
            key = "surfaces.sam.work_of_adhesion" if sam is not None else "surfaces.work_of_adhesion"
            raise SceneError(key, adhesion, f"must be > 0 J/m^2 when physics.adhesion_law = '{law}'", origin)


def _check_plasticity(si: dict, sam, origin: str) -> None:
    """The yield keys give a limiting contact pressure between the sphere's adhesive stress scale and E*
    (`continuum.physics.limiting_pressure`); physics.plasticity = 'on' needs an adhesive smooth sphere and a yield
    key."""
    choice = si["physics.plasticity"]
    if choice == "off":
        return
    sphere = si["contact"] == "smooth" and si["body.shape"] == "sphere"
    w = (sam.work_of_adhesion if sam is not None else si["surfaces.work_of_adhesion"])
    w = w if si["physics.adhesion_law"] != "none" else 0.0
    try:
        limits = partner_limits(si)
        if sphere:
            e_star = float(effective_modulus(si["surfaces.body.youngs_modulus"], si["surfaces.body.poisson_ratio"],
                                             si["surfaces.substrate.youngs_modulus"],
                                             si["surfaces.substrate.poisson_ratio"]))
            check_sphere_limits(limits, si["body.radius"], w, e_star)
    except InputError as err:
        raise SceneError(err.key, err.value, err.allowed, origin) from None
    if choice == "on" and not (sphere and w > 0.0 and limits):
        raise SceneError("physics.plasticity", "on", "the elastic-plastic law is for an adhesive smooth sphere "
                         "(contact = 'smooth', body.shape = 'sphere', work of adhesion > 0, adhesion law not 'none') "
                         "with surfaces.body or surfaces.substrate yield_strength or hardness", origin)


def _check_menisci(si: dict, sam, origin: str) -> None:
    """Menisci need mean-field rough contact or a smooth sphere, 0 < RH < 1 and both faces' water contact angles."""
    mode = si["surfaces.roughness.mode"]
    menisci = si["physics.menisci"]
    rh = si["environment.relative_humidity"]
    sphere = si["contact"] == "smooth" and si["body.shape"] == "sphere"
    if menisci == "on":
        if not sphere and (si["contact"] != "rough" or mode not in ("mean_field", "auto")):
            raise SceneError("physics.menisci", "on", "menisci are modelled for mean-field rough contact "
                             "(contact = 'rough', surfaces.roughness.mode = 'mean_field' or 'auto') and the smooth "
                             "sphere (contact = 'smooth', body.shape = 'sphere')", origin)
        if rh <= 0.0:
            raise SceneError("environment.relative_humidity", rh, "must be > 0 when physics.menisci = 'on'", origin)
    if menisci != "off" and (si["contact"] == "rough" or sphere) and rh > 0.0:
        if rh >= 1.0:
            raise SceneError("environment.relative_humidity", rh, "must be < 1 for menisci (the Kelvin radius "
                             "diverges at saturation); set physics.menisci = 'off' to ignore humidity", origin)
        keys = (("surfaces.sam.contact_angle",) if sam is not None
                else ("surfaces.body.contact_angle", "surfaces.substrate.contact_angle"))
        for key in keys:
            _require(si, key, origin, f"when environment.relative_humidity = {rh:g} > 0 and physics.menisci = "
                     f"'{menisci}' (the bridge force needs both faces' water contact angles; or set "
                     "physics.menisci = 'off')")


def _assemble(si: dict, mass: float, length: float | None, roughness, sam) -> Scene:
    """The Scene dataclass from the checked SI values; tolerance and grid from the fidelity preset unless given."""
    preset = FIDELITY[si["numerics.fidelity"]]
    default_rtol = preset["rtol_rough"] if si["contact"] == "rough" else preset["rtol"]
    rtol = si["numerics.rtol"] if si["numerics.rtol"] is not None else default_rtol
    grid_points = si["numerics.grid_points"] if si["numerics.grid_points"] is not None else preset["grid_points"]
    return Scene(
        **_section(Scene, si, "", name=si["name"]),
        body=Body(**_section(Body, si, "body", mass=mass, length=length)),
        surfaces=Surfaces(
            **_section(Surfaces, si, "surfaces", yield_strength=si["surfaces.substrate.yield_strength"],
                       hardness=si["surfaces.substrate.hardness"], roughness=roughness, sam=sam),
            body=Material(**_section(Material, si, "surfaces.body")),
            substrate=Material(**_section(Material, si, "surfaces.substrate"))),
        environment=Environment(**_section(Environment, si, "environment")),
        physics=Physics(**_section(Physics, si, "physics")),
        numerics=Numerics(**_section(Numerics, si, "numerics", rtol=rtol, grid_points=grid_points,
                                     table=preset["table"])),
        menisci=Menisci(**_section(Menisci, si, "menisci")),
    )


def _section(cls: type, si: dict, section: str, **given) -> dict:
    """Keyword arguments of `cls` (a generated section dataclass): `given` values, and every other attribute that
    is a key of `section` read from the SI values `si`. An attribute that is neither (a nested section, a value
    _build resolves) must be given by the caller."""
    prefix = f"{section}." if section else ""
    out = {}
    for f in dataclasses.fields(cls):
        if f.name in given:
            out[f.name] = given[f.name]
        elif f"{prefix}{f.name}" in si:
            out[f.name] = si[f"{prefix}{f.name}"]
    return out


def _nest(flat: dict) -> dict:
    out: dict = {}
    for path, value in flat.items():
        node = out
        *parents, leaf = path.split(".")
        for p in parents:
            node = node.setdefault(p, {})
        node[leaf] = value
    return out
