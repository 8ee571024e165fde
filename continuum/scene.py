"""Scene files: read, merge with a parameter set, validate at the edge, build frozen dataclasses.

Resolution order for every key: schema default < parameter set (`params = "NAME"` reads
`inputs/params/NAME.toml`, or `--params NAME|FILE` replaces it) < the scene file itself. The
resolved scene records each value and where it came from. Validation rejects unknown keys and
checks every value's type, sign and range; the first problem raises `SceneError` naming the key,
the value and what is allowed. Nothing here writes files.
"""
from __future__ import annotations

import hashlib
import json
import math
import tomllib
from dataclasses import asdict, dataclass
from pathlib import Path

from nanoimpact import data
from nanoimpact.errors import InputError

from .reference.hertz import effective_modulus
from .schema import FIDELITY, FIELD_BY_PATH, FIELDS, REQUIRED, Field, is_section, to_internal

#: The shipped parameter sets (inputs/params, installed as package data); names are looked up in
#: the user data folder first (nanoimpact.data).
PARAMS_DIR = data.shipped_root() / "params"


class SceneError(InputError):
    """An invalid scene: names the key, the value and what is allowed."""


# ----------------------------------------------------------------------------- dataclasses
@dataclass(frozen=True)
class Body:
    """The impacting body. Lengths in m, mass in kg."""

    shape: str
    radius: float
    length: float | None
    mass: float


@dataclass(frozen=True)
class Material:
    """Elastic constants (Pa, 1) and water contact angle (rad, or None if not given) of one surface."""

    youngs_modulus: float
    poisson_ratio: float
    contact_angle: float | None


@dataclass(frozen=True)
class Roughness:
    """Summit statistics of the (composite) rough surface: sigma (m), density (1/m^2), tip radius (m)."""

    sigma: float
    summit_density: float
    summit_radius: float
    datum: str
    mode: str
    seed: int
    summit_modulus: float | None = None


@dataclass(frozen=True)
class SAM:
    """A self-assembled monolayer on both surfaces: thickness (m), SAM-SAM work of adhesion (J/m^2),
    water contact angle (rad or None), and optionally its Young's modulus (Pa) and Poisson's ratio as a
    compliant layer in series with every summit (None: rigid layer)."""

    thickness: float | None
    work_of_adhesion: float
    contact_angle: float | None
    layer_modulus: float | None = None
    layer_poisson_ratio: float = 0.3
    interaction_range: float | None = None


@dataclass(frozen=True)
class Surfaces:
    """The pair of surfaces: work of adhesion (J/m^2), each side's material, roughness (or None).

    `yield_strength` and `hardness` (Pa, optional) are the substrate's, for the plasticity warnings.
    """

    work_of_adhesion: float
    body: Material
    substrate: Material
    roughness: Roughness | None = None
    yield_strength: float | None = None
    hardness: float | None = None
    sam: SAM | None = None
    interaction_range: float = 0.3e-9
    """z0 (m): range of the bare surfaces' attraction (Tabor parameter, Maugis-Dugdale stress)."""

    @property
    def interface_interaction_range(self) -> float:
        """z0 (m) of the contacting pair: the SAM's when both sides carry one and it is given."""
        if self.sam is not None and self.sam.interaction_range is not None:
            return self.sam.interaction_range
        return self.interaction_range

    @property
    def contact_angles(self) -> tuple[float | None, float | None]:
        """Water contact angles (rad) of the two contacting faces: the SAM's on both when covered."""
        if self.sam is not None:
            return self.sam.contact_angle, self.sam.contact_angle
        return self.body.contact_angle, self.substrate.contact_angle

    @property
    def interface_work_of_adhesion(self) -> float:
        """Work of adhesion (J/m^2) of the contacting pair: the SAM's when both sides carry one."""
        return self.sam.work_of_adhesion if self.sam is not None else self.work_of_adhesion

    @property
    def e_star(self) -> float:
        """Effective (contact) modulus E* in Pa, 1/E* = sum (1 - nu^2)/E (Johnson's convention)."""
        return float(effective_modulus(self.body.youngs_modulus, self.body.poisson_ratio,
                                       self.substrate.youngs_modulus, self.substrate.poisson_ratio))


@dataclass(frozen=True)
class Environment:
    """Gravity (m/s^2), relative humidity (fraction) and temperature (K)."""

    gravity: float
    relative_humidity: float
    temperature: float


@dataclass(frozen=True)
class Physics:
    """Model choices ('auto' entries are decided per scene in continuum.models)."""

    adhesion_law: str
    detachment: str
    line_stiffness: str
    half_space: str = "auto"
    menisci: str = "auto"


@dataclass(frozen=True)
class Menisci:
    """Capillary condensation settings: t_a (s) and its model, growth length h1 (m, None = from humidity),
    liquid surface tension (N/m) and molar volume (m^3/mol)."""

    condensation_time: float = 25e-6
    condensation_model: str = "fixed"
    growth_length: float | None = None
    surface_tension: float = 0.072
    molar_volume: float = 1.807e-5


@dataclass(frozen=True)
class Numerics:
    """Numerical settings; `rtol` is resolved from the fidelity preset unless given."""

    fidelity: str
    rtol: float
    max_bounces: int
    max_time: float
    rest_fraction: float
    samples_per_flight: int
    grid_points: int = 256
    table: str = "standard"


@dataclass(frozen=True)
class Scene:
    """A validated scene in SI units (angles in radians)."""

    name: str
    description: str
    contact: str
    release_height: float | None
    impact_velocity: float | None
    body: Body
    surfaces: Surfaces
    environment: Environment
    physics: Physics
    numerics: Numerics
    menisci: Menisci = Menisci()


@dataclass(frozen=True)
class ResolvedScene:
    """A scene together with the file-unit values it was built from and where each came from."""

    scene: Scene
    values: dict
    sources: dict
    scene_file: str | None
    params_file: str | None
    params_meta: dict | None = None

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
        except data.DataNotFound:
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
    except data.DataNotFound as exc:
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
    if values.get("name") is None:
        values["name"] = Path(scene_file).stem if scene_file is not None else "scene"
        sources["name"] = "file name"
    scene = _build(values, origin)
    return ResolvedScene(scene, values, sources, str(scene_file) if scene_file else None,
                         str(params_file) if params_file else None, params_meta)


def _require(values: dict, path: str, origin: str, why: str):
    if values.get(path) is None:
        raise SceneError(path, None, f"is required {why}", origin)
    return values[path]


def _build(v: dict, origin: str) -> Scene:
    """Cross-field checks, then the dataclasses (SI; degrees -> radians)."""
    for f in FIELDS:
        if f.default is REQUIRED and f.path not in v:
            raise SceneError(f.path, None, f"is required: {f.allowed()}", origin)
    si = {path: to_internal(FIELD_BY_PATH[path], val) for path, val in v.items()}

    if (si["release_height"] is None) == (si["impact_velocity"] is None):
        raise SceneError("release_height", si["release_height"],
                         "give exactly one of release_height and impact_velocity", origin)
    if si["release_height"] is not None and si["environment.gravity"] == 0.0:
        raise SceneError("environment.gravity", 0.0, "must be > 0 when the body is released from a height", origin)

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

    roughness = None
    if si["contact"] == "rough":
        if shape != "cylinder":
            raise SceneError("contact", "rough", "rough contact is modelled for a roller (body.shape = 'cylinder', "
                             "plane-strain line contact) only", origin)
        for key in ("sigma", "summit_density", "summit_radius"):
            _require(si, f"surfaces.roughness.{key}", origin, "for contact = 'rough'")
        roughness = Roughness(si["surfaces.roughness.sigma"], si["surfaces.roughness.summit_density"],
                              si["surfaces.roughness.summit_radius"], si["surfaces.roughness.datum"],
                              si["surfaces.roughness.mode"], si["surfaces.roughness.seed"],
                              si["surfaces.roughness.summit_modulus"])

    sam = None
    if si["surfaces.sam.coverage"] == "both":
        sam = SAM(si["surfaces.sam.thickness"],
                  _require(si, "surfaces.sam.work_of_adhesion", origin, "when surfaces.sam.coverage = 'both'"),
                  si["surfaces.sam.contact_angle"], si["surfaces.sam.layer_modulus"],
                  si["surfaces.sam.layer_poisson_ratio"], si["surfaces.sam.interaction_range"])
        if sam.layer_modulus is not None:
            _require(si, "surfaces.sam.thickness", origin, "when surfaces.sam.layer_modulus is set (the layer's "
                     "compliance is thickness / modulus)")
    elif si["surfaces.sam.layer_modulus"] is not None:
        raise SceneError("surfaces.sam.layer_modulus", v["surfaces.sam.layer_modulus"],
                         "is for a SAM; set surfaces.sam.coverage = 'both' or remove it", origin)
    adhesion = sam.work_of_adhesion if sam is not None else si["surfaces.work_of_adhesion"]

    law = si["physics.adhesion_law"]
    if law in ("jkr", "dmt", "maugis_dugdale"):
        if shape == "cylinder" and si["contact"] == "smooth":
            raise SceneError("physics.adhesion_law", law,
                             "a smooth cylinder has no adhesive law here (2-D JKR is not implemented); "
                             "use body.shape = 'sphere' or contact = 'rough'", origin)
        if law != "jkr" and si["contact"] == "smooth":
            raise SceneError("physics.adhesion_law", law, "a smooth sphere takes 'none', 'jkr' or 'auto'; "
                             "DMT and Maugis-Dugdale are summit laws of rough contact", origin)
        if adhesion <= 0.0:
            key = "surfaces.sam.work_of_adhesion" if sam is not None else "surfaces.work_of_adhesion"
            raise SceneError(key, adhesion, f"must be > 0 J/m^2 when physics.adhesion_law = '{law}'", origin)
    if si["contact"] == "rough" and si["surfaces.roughness.mode"] == "discrete" and law in ("dmt", "maugis_dugdale"):
        raise SceneError("physics.adhesion_law", law, "discrete summits use JKR or Hertz; DMT and Maugis-Dugdale "
                         "summits run in surfaces.roughness.mode = 'averaged'", origin)

    menisci = si["physics.menisci"]
    rh = si["environment.relative_humidity"]
    if menisci == "on":
        if si["contact"] != "rough" or si["surfaces.roughness.mode"] != "averaged":
            raise SceneError("physics.menisci", "on", "menisci are modelled for averaged rough contact only "
                             "(contact = 'rough', surfaces.roughness.mode = 'averaged')", origin)
        if rh <= 0.0:
            raise SceneError("environment.relative_humidity", rh, "must be > 0 when physics.menisci = 'on'", origin)
    if menisci != "off" and si["contact"] == "rough" and rh > 0.0:
        if rh >= 1.0:
            raise SceneError("environment.relative_humidity", rh, "must be < 1 for menisci (the Kelvin radius "
                             "diverges at saturation); set physics.menisci = 'off' to ignore humidity", origin)
        keys = (("surfaces.sam.contact_angle",) if sam is not None
                else ("surfaces.body.contact_angle", "surfaces.substrate.contact_angle"))
        for key in keys:
            _require(si, key, origin, f"when environment.relative_humidity = {rh:g} > 0 and physics.menisci = "
                     f"'{menisci}' (the bridge force needs both faces' water contact angles; or set "
                     "physics.menisci = 'off')")

    preset = FIDELITY[si["numerics.fidelity"]]
    default_rtol = preset["rtol_rough"] if si["contact"] == "rough" else preset["rtol"]
    rtol = si["numerics.rtol"] if si["numerics.rtol"] is not None else default_rtol
    grid_points = si["numerics.grid_points"] if si["numerics.grid_points"] is not None else preset["grid_points"]
    return Scene(
        name=si["name"],
        description=si["description"],
        contact=si["contact"],
        release_height=si["release_height"],
        impact_velocity=si["impact_velocity"],
        body=Body(shape, si["body.radius"], length, mass),
        surfaces=Surfaces(
            si["surfaces.work_of_adhesion"],
            Material(si["surfaces.body.youngs_modulus"], si["surfaces.body.poisson_ratio"],
                     si["surfaces.body.contact_angle"]),
            Material(si["surfaces.substrate.youngs_modulus"], si["surfaces.substrate.poisson_ratio"],
                     si["surfaces.substrate.contact_angle"]),
            roughness, si["surfaces.substrate.yield_strength"], si["surfaces.substrate.hardness"], sam,
            si["surfaces.interaction_range"],
        ),
        environment=Environment(si["environment.gravity"], si["environment.relative_humidity"],
                                si["environment.temperature"]),
        physics=Physics(si["physics.adhesion_law"], si["physics.detachment"], si["physics.line_stiffness"],
                        si["physics.half_space"], si["physics.menisci"]),
        numerics=Numerics(si["numerics.fidelity"], rtol, si["numerics.max_bounces"], si["numerics.max_time"],
                          si["numerics.rest_fraction"], si["numerics.samples_per_flight"], grid_points,
                          preset["table"]),
        menisci=Menisci(si["menisci.condensation_time"], si["menisci.condensation_model"],
                        si["menisci.growth_length"], si["menisci.surface_tension"], si["menisci.molar_volume"]),
    )


def _nest(flat: dict) -> dict:
    out: dict = {}
    for path, value in flat.items():
        node = out
        *parents, leaf = path.split(".")
        for p in parents:
            node = node.setdefault(p, {})
        node[leaf] = value
    return out
