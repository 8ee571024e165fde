"""The scene-file schema: one table of fields drives validation, defaults and `docs/scenes.md`.

Scene files are TOML in SI units; angles are written in degrees and converted to radians
here, at the edge (the only unit conversion a scene needs). Every field states its type, unit,
allowed range and default. `REQUIRED` marks fields without a default; `None` as a default
marks optional fields whose absence means "not given" (the model that needs them says so).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from nanoimpact import fields
from nanoimpact.errors import InputError
from nanoimpact.fields import REQUIRED


@dataclass(frozen=True)
class Field(fields.Field):
    """One scene key (`nanoimpact.fields.Field`: type, unit, range, default, doc, the check and the JSON
    Schema), plus `degrees`: an angle written in degrees in the file and stored in radians."""

    degrees: bool = False

    @property
    def path(self) -> str:
        """The dotted key ("body.radius")."""
        return self.key


@dataclass(frozen=True)
class NumberOrWord(Field):
    """A number key that also takes one of a few words (`words`), e.g. surfaces.roughness.members = "auto"."""

    words: tuple[str, ...] = ()

    def allowed(self) -> str:
        return super().allowed() + "".join(f" or {w!r}" for w in self.words)

    def check(self, value, origin: str = "", *, error=fields.InputError, name: str | None = None):
        if isinstance(value, str) and value in self.words:
            return value
        if isinstance(value, str):
            raise error(name or self.key, value, f"must be {self.allowed()}", origin)
        return super().check(value, origin, error=error, name=name)

    def type_name(self) -> str:
        return f"{self.kind.__name__} or " + " or ".join(repr(w) for w in self.words)

    def json_schema(self) -> dict:
        out = super().json_schema()
        number = {k: out.pop(k) for k in ("type", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")
                  if k in out}
        return {"anyOf": [number, {"enum": list(self.words)}], **out}


@dataclass(frozen=True)
class _OneOrList(Field):
    """A string key that also takes a list of one or more strings (`topography = "a.di"` or `["a.di", "b.di"]`);
    the value is kept as given."""

    def _list(self) -> Field:
        return Field(self.key, list, self.unit, "", item=str)

    def check(self, value, origin="", *, error=None, name=None):
        kw = {} if error is None else {"error": error}
        if isinstance(value, list):
            try:
                return self._list().check(value, origin, name=name, **kw)
            except InputError as exc:
                raise type(exc)(exc.key, exc.value, f"must be {self.allowed()}", origin) from None
        return super().check(value, origin, name=name, **kw)

    def allowed(self) -> str:
        return f"a string, or {self._list().allowed()}"

    def json_schema(self) -> dict:
        out = super().json_schema()
        out.pop("type")
        listed = {k: v for k, v in self._list().json_schema().items() if k in ("type", "items", "minItems")}
        return {"anyOf": [{"type": "string"}, listed], **out}


@dataclass(frozen=True)
class _IndexOrName(Field):
    """A string key that also takes an index (an integer from `low` to `high`): a channel by name or by index."""

    def _index(self) -> Field:
        return Field(self.key, int, "1", "", low=self.low, high=self.high)

    def check(self, value, origin="", *, error=None, name=None):
        kw = {} if error is None else {"error": error}
        if isinstance(value, int) and not isinstance(value, bool):
            try:
                return self._index().check(value, origin, name=name, **kw)
            except InputError as exc:
                raise type(exc)(exc.key, value, f"must be {self.allowed()}", origin) from None
        if isinstance(value, str) and not value:
            raise (error or InputError)(name or self.key, value, f"must be {self.allowed()}", origin)
        return super().check(value, origin, name=name, **kw)

    def allowed(self) -> str:
        return f"a name (a non-empty string), or an index: {self._index().allowed()}"

    def json_schema(self) -> dict:
        out = super().json_schema()
        index = {k: v for k, v in self._index().json_schema().items() if k in ("type", "minimum", "maximum")}
        out.pop("type")
        return {"anyOf": [{"type": "string", "minLength": 1}, index], **out}


_LEN = dict(kind=float, unit="m")
_MODULUS = dict(kind=float, unit="Pa", low=1e6, high=1e13)
_POISSON = dict(kind=float, unit="1", low=0.0, high=0.5, high_open=True)
_ANGLE = dict(kind=float, unit="deg", low=0.0, high=180.0, degrees=True)

FIELDS: tuple[Field, ...] = (
    # --- top level -----------------------------------------------------------------------
    Field("name", str, "", "Scene name (defaults to the file name without extension).", None),
    Field("description", str, "", "Free text shown in results.", ""),
    Field("params", str, "", "Parameter set: reads inputs/params/NAME.toml; scene values override it.", None),
    Field("contact", str, "", "Contact model: 'smooth' (Hertz/JKR of the body's own curvature) or 'rough' "
          "(Greenwood-Williamson summits on the substrate under the body).", "smooth", choices=("smooth", "rough")),
    Field("release_height", float, "m", "Release height of the lowest point of the body above the contact "
          "datum, from rest. Give exactly one of release_height and impact_velocity.", None,
          low=0.0, high=1.0, low_open=True),
    Field("impact_velocity", float, "m/s", "Normal speed at first touch (the body starts at the datum "
          "moving down). Give exactly one of release_height and impact_velocity.", None,
          low=0.0, high=100.0, low_open=True),
    # --- body ----------------------------------------------------------------------------
    Field("body.shape", str, "", "Body geometry.", REQUIRED, choices=("cylinder", "sphere")),
    Field("body.radius", doc="Radius of the cylinder or sphere.", default=REQUIRED,
          low=1e-9, high=1.0, **_LEN),
    Field("body.length", doc="Cylinder (roller) length l; cylinders only.", default=None,
          low=1e-9, high=10.0, **_LEN),
    Field("body.mass", float, "kg", "Body mass. Give mass or density, not both.", None,
          low=0.0, high=1e3, low_open=True),
    Field("body.density", float, "kg/m^3", "Body density; mass follows from the shape.", None,
          low=1.0, high=1e5),
    # --- surfaces ------------------------------------------------------------------------
    Field("surfaces.work_of_adhesion", float, "J/m^2", "Work of adhesion (Dupre): gamma1 + gamma2 - gamma12.",
          0.0, low=0.0, high=10.0),
    Field("surfaces.body.youngs_modulus", doc="Young's modulus of the body.", default=REQUIRED, **_MODULUS),
    Field("surfaces.body.poisson_ratio", doc="Poisson's ratio of the body.", default=REQUIRED, **_POISSON),
    Field("surfaces.body.contact_angle", doc="Water contact angle on the body (menisci).",
          default=None, **_ANGLE),
    Field("surfaces.body.work_of_adhesion_sl", float, "J/m^2", "Solid-water work of adhesion W_SL of the body "
          "(MD thermodynamic integration): inside a bridge the solids adhere with W_wet = dgamma + 2 gamma_lv "
          "- W_1L - W_2L (docs/model.md, Menisci). Not given: gamma_lv (1 + cos theta) from the contact angle.",
          None, low=0.0, high=10.0),
    Field("surfaces.body.yield_strength", float, "Pa", "Tensile yield strength Y of the body: a smooth sphere's "
          "limiting contact pressure 2.8 Y (Tabor) in the Thornton-Ning elastic-plastic law (physics.plasticity; "
          "the softer partner's counts). Optional.", None, low=1e6, high=1e12),
    Field("surfaces.body.hardness", float, "Pa", "Indentation hardness H of the body: a smooth sphere's limiting "
          "contact pressure (H is used when both it and the yield strength are given). Optional.", None,
          low=1e6, high=1e12),
    Field("surfaces.substrate.youngs_modulus", doc="Young's modulus of the substrate.", default=REQUIRED,
          **_MODULUS),
    Field("surfaces.substrate.poisson_ratio", doc="Poisson's ratio of the substrate.", default=REQUIRED,
          **_POISSON),
    Field("surfaces.substrate.contact_angle", doc="Water contact angle on the substrate (menisci).",
          default=None, **_ANGLE),
    Field("surfaces.substrate.work_of_adhesion_sl", float, "J/m^2", "Solid-water work of adhesion W_SL of the "
          "substrate "
          "(MD thermodynamic integration): inside a bridge the solids adhere with W_wet = dgamma + 2 gamma_lv "
          "- W_1L - W_2L (docs/model.md, Menisci). Not given: gamma_lv (1 + cos theta) from the contact angle.",
          None, low=0.0, high=10.0),
    Field("surfaces.substrate.yield_strength", float, "Pa", "Tensile yield strength of the substrate: a smooth "
          "sphere's limiting contact pressure 2.8 Y (as surfaces.body.yield_strength); rough and line contact warn "
          "when the contact pressure passes the Tresca/von Mises onset (optional).", None, low=1e6, high=1e12),
    Field("surfaces.substrate.hardness", float, "Pa", "Indentation hardness of the substrate (and its summits): a "
          "smooth sphere's limiting contact pressure; the summits' limiting pressure in the plasticity index of rough "
          "contact (physics.plasticity; optional).", None,
          low=1e6, high=1e12),
    Field("surfaces.sam.coverage", str, "", "Self-assembled monolayer: 'none', or 'both' (both surfaces covered; "
          "the SAM-SAM work of adhesion replaces surfaces.work_of_adhesion).", "none", choices=("none", "both")),
    Field("surfaces.sam.thickness", float, "m", "SAM thickness (OTS ~2-2.5 nm). A uniform layer that conforms to "
          "the summits shifts every gap equally; its compliance is a later model.", None, low=1e-10, high=1e-7),
    Field("surfaces.sam.work_of_adhesion", float, "J/m^2", "Work of adhesion between the two SAM-covered "
          "surfaces.", None, low=0.0, high=10.0),
    Field("surfaces.sam.contact_angle", doc="Water contact angle on the SAM.", default=None, **_ANGLE),
    Field("surfaces.sam.work_of_adhesion_sl", float, "J/m^2", "Solid-water work of adhesion W_SL of the SAM "
          "(MD thermodynamic integration): inside a bridge the solids adhere with W_wet = dgamma + 2 gamma_lv "
          "- W_1L - W_2L (docs/model.md, Menisci). Not given: gamma_lv (1 + cos theta) from the contact angle.",
          None, low=0.0, high=10.0),
    Field("surfaces.sam.layer_modulus", float, "Pa", "Young's modulus of the SAM as a compliant layer on every "
          "summit (rough contact; needs surfaces.sam.thickness): the summits' contact modulus becomes the coated "
          "pair's equivalent modulus (Perriot & Barthel 2004; docs/model.md, Coated summits). Not set: the layer is "
          "rigid and only shifts every gap equally.", None, low=1e6, high=1e12),
    Field("surfaces.sam.layer_poisson_ratio", doc="Poisson's ratio of the SAM layer (its plane-strain modulus).",
          default=0.3, **_POISSON),
    Field("surfaces.sam.interaction_range", float, "m", "Range z0 of the SAM-SAM attraction (Tabor parameter, "
          "Maugis-Dugdale stress) when both surfaces are covered; not set: surfaces.interaction_range.", None,
          low=5e-11, high=1e-8),
    Field("surfaces.interaction_range", float, "m", "Range z0 of the surface attraction (equilibrium separation "
          "of the Lennard-Jones surface law): sets the summits' Tabor parameter and the Maugis-Dugdale stress "
          "1.03 dgamma/z0. Default 0.3 nm (Tabor 1977; Johnson & Greenwood 1997).", 0.3e-9, low=5e-11, high=1e-8),
    Field("surfaces.roughness.sigma", float, "m", "Standard deviation of summit heights (composite of both "
          "surfaces; the paper's 'average asperity height'). Required for contact = 'rough' unless a height map "
          "(topography or synthetic) gives it.", None,
          low=1e-11, high=1e-5),
    Field("surfaces.roughness.summit_density", float, "1/m^2", "Summits per unit nominal area (n).", None,
          low=1e6, high=1e20),
    Field("surfaces.roughness.summit_radius", float, "m", "Tip radius of every summit (beta).", None,
          low=1e-10, high=1e-2),
    Field("surfaces.roughness.summit_modulus", float, "Pa", "Effective modulus E* of the contacts "
          "of bare summits; default: E* of the two surfaces' materials. A SAM with a layer modulus coats them.", None,
          low=1e6, high=1e13),
    Field("surfaces.roughness.datum", str, "", "Where release_height is measured from: the tallest summit "
          "expected in the nominal footprint (default), or the summits' mean plane.", "tallest_summit",
          choices=("tallest_summit", "mean_plane")),
    Field("surfaces.roughness.mode", str, "", "'mean_field' (the Greenwood-Williamson average of the summits), "
          "'discrete' (one seeded realisation of individual summits along the footprint, same laws), 'ensemble' "
          "(surfaces.roughness.members discrete realisations, reported as distributions next to the mean-field "
          "run), or 'auto': an ensemble when the first impact's expected summits in contact are fewer than "
          "continuum.model.decisions.ENSEMBLE_BELOW_CONTACTS (measured, docs/model.md 'Few summits'), else the mean "
          "field.", "mean_field", choices=("auto", "mean_field", "discrete", "ensemble")),
    Field("surfaces.roughness.seed", int, "1", "Random seed of the discrete summit realisation; of an ensemble, "
          "the master seed its members' seeds are derived from (numpy SeedSequence).", 0, low=0, high=2**63 - 1),
    NumberOrWord("surfaces.roughness.members", int, "1", "Realisations in an ensemble (mode 'ensemble', or 'auto' "
                 "where it runs one); 'auto' adds members in batches (continuum.dynamics.ensemble_run.AUTO_BATCH) "
                 "until the Wilson 95 % half-width of the stick probabilities (first impact and within the run) is "
                 "below surfaces.roughness.target_half_width, or surfaces.roughness.max_members are run; "
                 "result.json -> ensemble.members_rule records why it stopped.", 64, low=2, high=100000,
                 words=("auto",)),
    Field("surfaces.roughness.target_half_width", float, "1", "members = 'auto': the Wilson 95 % half-width of "
          "the stick probabilities at which the ensemble stops growing.", 0.05, low=0.0, high=0.5, low_open=True),
    Field("surfaces.roughness.max_members", int, "1", "members = 'auto': the most members run.", 512, low=2,
          high=100000),
    Field("surfaces.roughness.tail_model", str, "", "The summit-height distribution an ensemble's members draw "
          "their strip from: 'gaussian' (of sigma, the Greenwood-Williamson surface of the mean field), or, for a "
          "height map, 'empirical_gpd' (the map's own summit heights with a generalised Pareto tail fitted over a "
          "threshold, continuum.rough.tail). With a map the ensemble is also run under the other model and both "
          "are reported (result.json -> ensemble.tail_models).", "gaussian", choices=("gaussian", "empirical_gpd")),
    Field("surfaces.roughness.escape_velocities", bool, "", "Of an ensemble, also bisect each member's escape "
          "velocity (the smallest first-impact speed from which it rebounds, continuum.dynamics.escape) and report "
          "their percentiles in result.json -> ensemble -> escape_velocity; each member then runs a dozen or more "
          "single impacts besides its drop.", False),
    _OneOrList("surfaces.roughness.topography", str, "", "A measured height map (any format SurfaceTopography "
               "reads: NanoScope .di, Gwyddion .gwy, Nanosurf .nid, Asylum .ibw, matrix text, .npy), or a list of "
               "scans of one surface at different sizes (each takes part at the cutoff where it resolves it; their "
               "summits are pooled); a relative path is looked up beside the scene file, then in the data folders. "
               "The summit statistics fill sigma, summit_density and summit_radius (replacing the parameter set's; "
               "giving them in the scene too is an error).", None),
    _IndexOrName("surfaces.roughness.topography_channel", str, "", "Channel of the topography file: its index, "
                 "or its name as the file spells it ('Height', 'ZSensor'). Must hold heights (never phase, "
                 "amplitude, deflection, error). Not set: the file's only height channel, or among several the "
                 "closed-loop sensor channel (else the first), with a warning naming the others.", None, low=0,
                 high=1000),
    Field("surfaces.roughness.topography_detrend", str, "", "Levelling of a measured map: 'plane' (least-squares "
          "plane), 'line' (each scan line's offset and tilt, SurfaceTopography scan_line_align) or 'none' (mean "
          "only). Recorded in result.json (surface.source.detrend) with the variance removed; 'plane' warns where "
          "scan-line offsets carry more than a quarter of the variance.", "plane", choices=("plane", "line", "none")),
    Field("surfaces.roughness.topography_size", list, "m", "Physical size [L] or [Lx, Ly] of a topography file "
          "that has none (refused where the file has its own).", None, item=float, length=(1, 2), low=1e-9,
          high=1.0),
    Field("surfaces.roughness.topography_unit", str, "", "Height unit of a topography file that has none "
          "(refused where the file has its own).", None, choices=("m", "mm", "um", "nm", "pm")),
    Field("surfaces.roughness.summit_route", str, "", "How a height map gives summit statistics: 'direct' "
          "(summits found on the filtered grid: 8-neighbour maxima, curvature of a 3x3 quadratic fit; measures the "
          "map as it is) or 'spectral' (Nayak/McCool from the spectral moments m0, m2, m4; assumes an isotropic "
          "Gaussian surface, which scan artefacts and non-Gaussian heights break). Both are recorded in result.json "
          "(surface.routes).", "direct", choices=("direct", "spectral")),
    Field("surfaces.roughness.summit_cutoff", float, "m", "Shortest wavelength kept for summit statistics (the map "
          "is low-pass filtered there; >= 4 pixels): summit radius and density depend on it. Required with a "
          "measured map unless tip_radius is given; a synthetic map defaults to its short_cutoff.", None,
          low=1e-10, high=1e-3),
    Field("surfaces.roughness.summit_cutoff_from", str, "", "'bem': the summit cutoff is measured on the map, where "
          "its discrete summits lose per quasi-static cycle the energy the boundary-element reference loses "
          "(continuum/rough/cutoff_match.py; a square map of at most 256^2 points whose grid resolves the cohesive "
          "zone; minutes per map, cached by its hash and the law). Instead of summit_cutoff and tip_radius; "
          "result.json's surface.cutoff_from records the origin (kind 'bem', the match error, whether the "
          "reference's loss converged).", None, choices=("bem",)),
    Field("surfaces.roughness.tip_radius", float, "m", "AFM tip radius: the cutoff becomes the shortest wavelength "
          "the tip resolves (SurfaceTopography's scanning_probe_reliability_cutoff; Sanner et al. 2022). Instead "
          "of summit_cutoff.", None, low=1e-10, high=1e-4),
    Field("surfaces.roughness.synthetic.hurst", float, "1", "Synthetic self-affine surface (Fourier synthesis, "
          "SurfaceTopography): Hurst exponent H, C(q) ~ q^(-2-2H).", None, low=0.0, high=1.0, low_open=True),
    Field("surfaces.roughness.synthetic.rms_height", float, "m", "Synthetic surface: rms height.", None,
          low=1e-11, high=1e-5),
    Field("surfaces.roughness.synthetic.short_cutoff", float, "m", "Synthetic surface: shortest wavelength "
          "(>= 4 pixels); also the summit cutoff unless summit_cutoff is given.", None, low=1e-10, high=1e-3),
    Field("surfaces.roughness.synthetic.long_cutoff", float, "m", "Synthetic surface: roll-off wavelength (flat "
          "spectrum above it); not set: self-affine up to the map size.", None, low=1e-10, high=1e-2),
    Field("surfaces.roughness.synthetic.size", float, "m", "Synthetic surface: side of the square periodic map.",
          None, low=1e-9, high=1e-2),
    Field("surfaces.roughness.synthetic.grid_points", int, "1", "Synthetic surface: grid points along each side.",
          256, low=16, high=4096),
    Field("surfaces.roughness.synthetic.seed", int, "1", "Synthetic surface: seed of its random phases and "
          "amplitudes (NumPy default_rng); independent of surfaces.roughness.seed (discrete summits).", 0,
          low=0, high=2**63 - 1),
    # --- environment ---------------------------------------------------------------------
    Field("environment.gravity", float, "m/s^2", "Gravitational acceleration (0 switches gravity off).",
          9.80665, low=0.0, high=1e3),
    Field("environment.relative_humidity", float, "1", "Relative humidity as a fraction (0-1).", 0.0,
          low=0.0, high=1.0),
    Field("environment.temperature", float, "K", "Temperature.", 298.15, low=0.0, high=2000.0, low_open=True),
    # --- physics -------------------------------------------------------------------------
    Field("physics.adhesion_law", str, "", "Summit (or sphere) law: 'none' (Hertz), 'jkr' (JKR with Fuller-Tabor "
          "hysteresis), 'dmt' (no loop), 'maugis_dugdale' (jump-in/out from its own solution), or 'auto': from the "
          "Tabor parameter (> 5 JKR, < 0.1 DMT, else Maugis-Dugdale), left out when its estimated loss per impact "
          "is negligible (rough contact). A smooth sphere takes all five ('auto' by its own Tabor parameter; "
          "DMT and Maugis-Dugdale with displacement-controlled release only).",
          "auto", choices=("auto", "none", "jkr", "dmt", "maugis_dugdale")),
    Field("physics.detachment", str, "", "JKR detachment criterion: 'displacement' (let go at -delta_c, as "
          "the paper) or 'load' (let go at -P_c).", "displacement", choices=("displacement", "load")),
    Field("physics.plasticity", str, "", "Smooth sphere: the Thornton-Ning (1998) adhesive elastic-plastic law "
          "(JKR to yield, then a limiting contact pressure from the softer partner's hardness or 2.8 x yield "
          "strength; the flattening is carried into later impacts). 'auto': on when the first impact is faster "
          "than the yield velocity, off (recorded) when no yield key is given. Rough contact: 'auto' runs "
          "Thornton-Ning summits where their plasticity index psi = (E*/p_y) sqrt(sigma/beta) >= 0.6 (Greenwood & "
          "Williamson 1966) or the first impact's estimated depth passes their yield approach, and they are JKR "
          "summits over a rigid substrate without bridges, in the mean field or discrete (else elastic summits, "
          "recorded with psi).", "auto",
          choices=("auto", "on", "off")),
    Field("physics.line_stiffness", str, "", "Hertz line contact: 'implicit' solves W = pi l E* delta/(2 ln(2l/b)+1) "
          "with b(W) exactly; 'constant' freezes K at the first impact's peak load (paper eq 2).",
          "implicit", choices=("implicit", "constant")),
    Field("physics.half_space", str, "", "Rough contact: couple the summits to the elastic half-space "
          "under them (eqs 16-17, FFT influence coefficients), treat the substrate below the summits as rigid, or "
          "'auto': on unless its estimated deflection across the footprint is below 1e-3 sigma.",
          "auto", choices=("auto", "on", "off")),
    Field("physics.menisci", str, "", "Capillary bridges after the condensation time (section 'menisci'): at "
          "the summits of rough contact (mean field, or each summit of a discrete realisation and of every ensemble "
          "member), or one bridge at a smooth sphere's contact. 'auto': left out "
          "when dry, hydrophobic (cos t1 + cos t2 <= 0), for a sphere when the Kelvin radius is below "
          "menisci.min_kelvin_radius, or when no contact of the dry run lasts the condensation time.", "auto",
          choices=("auto", "on", "off")),
    # --- menisci -------------------------------------------------------------------------
    Field("menisci.condensation_time", float, "s", "t_a: contact time before the first bridges form "
          "(25 us, the paper's value from Riedo et al. 2002). Used when condensation_model = 'fixed'.", 25e-6,
          low=0.0, high=1e3, low_open=True),
    Field("menisci.condensation_model", str, "", "'fixed' (t_a = condensation_time) or 'nucleation' (thermally "
          "activated: t_a = tau0 exp(dE(RH)/kT), dE = 7.8e-20 J ln(1/RH)/ln(1/0.4), tau0 = 2.6e-11 s, fitted to "
          "Szoszkiewicz & Riedo 2005: 4.2 ms at 40% RH, 299 K).", "fixed", choices=("fixed", "nucleation")),
    Field("menisci.solid_adhesion", str, "", "Solid-solid adhesion of a summit inside a bridge: 'wet' (the work "
          "of adhesion under the liquid, dgamma + 2 gamma_lv - W_1L - W_2L, Israelachvili 2011 §17.7: the bridge "
          "replaces part of the dry pull; discrete summits take their whole law, loop included, at it) or 'additive' "
          "(the paper's eq 14: bridges add to the dry dgamma).", "wet",
          choices=("wet", "additive")),
    Field("menisci.growth_length", float, "m", "h1 in h_mw(t) = h1 ln(t/t_a), the growth of the bridgeable gap "
          "(Riedo et al. 2002). Not set: 1/(n_w d_w^2 ln(1/RH)), one water molecule's cross-section d_w^2 as the "
          "condensing column.", None, low=1e-12, high=1e-6),
    Field("menisci.surface_tension", float, "N/m", "Liquid-vapour surface tension gamma_lv (water 0.072 at 25 C; "
          "SPC/E water 0.0636).", 0.072, low=1e-3, high=1.0),
    Field("menisci.molar_volume", float, "m^3/mol", "Molar volume of the liquid (Kelvin radius; water 1.807e-5).",
          1.807e-5, low=1e-6, high=1e-3),
    Field("menisci.min_kelvin_radius", float, "m", "Smooth sphere: no bridge condenses where the Kelvin radius is "
          "below this (a meniscus narrower than a molecule is no continuum liquid). Not set: one water molecule, "
          "n_w^(-1/3) = 0.31 nm.", None, low=1e-11, high=1e-8),
    # --- numerics ------------------------------------------------------------------------
    Field("numerics.fidelity", str, "", "Preset for tolerances (and later grid and table sizes).", "standard",
          choices=("fast", "standard", "reference")),
    Field("numerics.rtol", float, "1", "Relative tolerance of the contact integrator (overrides the preset).",
          None, low=1e-14, high=1e-3),
    Field("numerics.grid_points", int, "1", "Rough contact: grid points across the footprint (overrides the "
          "preset).", None, low=16, high=65536),
    Field("numerics.max_bounces", int, "1", "Stop after this many impacts.", 100, low=1, high=100000),
    Field("numerics.max_time", float, "s", "Stop after this much simulated time.", 10.0, low=0.0, high=1e6,
          low_open=True),
    Field("numerics.rest_fraction", float, "1", "A rebound lower than this fraction of the release height "
          "counts as coming to rest (the notes' 1e-3 h0).", 1e-3, low=0.0, high=1.0, low_open=True, high_open=True),
    Field("numerics.audit_tolerance", float, "1", "Largest energy-audit error (energy_audit.max_relative_error: "
          "max |E(t) - E(0)| over the first impact's kinetic energy) the run accepts without a warning in "
          "result.json -> warnings. Not set: no check (the audit is recorded either way).", None, low=0.0, high=1.0,
          low_open=True),
    Field("numerics.samples_per_flight", int, "1", "Time-series samples written per free flight.", 64,
          low=2, high=100000),
)

FIELD_BY_PATH = {f.path: f for f in FIELDS}
SECTIONS = sorted({f.path.rsplit(".", 1)[0] for f in FIELDS if "." in f.path})

#: Fidelity presets: integrator tolerance (smooth laws; rough contact has its own, because its
#: force has a kink wherever a grid cell reaches the tallest summit and the GW tables carry ~1e-6
#: error anyway), grid points across a rough footprint, GW table resolution. The error of `fast`
#: and `standard` against `reference` is measured in benchmarks/bench_fidelity.py.
FIDELITY = {
    "fast": {"rtol": 1e-7, "rtol_rough": 1e-6, "grid_points": 64, "table": "fast"},
    "standard": {"rtol": 1e-10, "rtol_rough": 1e-8, "grid_points": 128, "table": "standard"},
    "reference": {"rtol": 1e-12, "rtol_rough": 1e-10, "grid_points": 512, "table": "reference"},
}


def is_section(path: str) -> bool:
    """True if `path` names a table (section) of the schema rather than a value."""
    return path in SECTIONS


def to_internal(f: Field, value):
    """Convert a validated file value to SI-internal form (degrees -> radians)."""
    if value is None:
        return None
    if f.degrees:
        return math.radians(value)
    return value


def schema_markdown() -> str:
    """The schema as a markdown table, for docs/scenes.md (generated, so it cannot drift)."""
    return fields.markdown_table(FIELDS, [("key", lambda f: f"`{f.path}`"), ("type", lambda f: f.kind.__name__),
                                          ("unit", lambda f: f.unit or ""), ("allowed", lambda f: f.allowed()),
                                          ("default", Field.default_text), ("meaning", lambda f: f.doc)])


def json_schema() -> dict:
    """JSON Schema of a scene file (and of a parameter set, whose keys are scene keys; `[meta]` is free)."""
    doc = fields.json_schema(((f.path, f) for f in FIELDS), title="nanoimpact scene", required=False,
                             description="A scene file or parameter set (TOML, SI units; angles in degrees). "
                                         "Required keys may come from the scene's parameter set, so none is "
                                         "required here; the loader checks the merged scene. See docs/scenes.md.")
    doc["properties"]["meta"] = {"type": "object", "description": "Parameter sets: description, provenance, and "
                                 "[meta.origin], each value's origin (continuum.origins)."}
    return doc


if __name__ == "__main__":  # python -m continuum.schema  -> prints the table for docs/scenes.md
    print(schema_markdown())
