"""A roller on a seeded random realisation of individual JKR summits: the discrete reference.

The averaged law (`rough_roller.py`, `rough_rigid.py`) replaces the summits under the roller by
their Greenwood-Williamson average. That is good when many summits carry the load and poor when a
handful do (the paper's roller touches a few). This law keeps the same per-summit physics (JKR
spheres with Fuller-Tabor hysteresis, `continuum.reference.jkr`; Hertz spheres without adhesion)
and the same coordinates, but on one random surface drawn from the same statistics, so the
difference between the two measures where the average stops holding.

Realisation (seeded, `numpy.random.default_rng(seed)`): in the nominal footprint strip |x| <= x_f
(`continuum.rough.datum.tallest_summit`) along the roller length l, a Poisson number of summits
(mean n 2 x_f l) at uniform positions (x_i, y_i), heights z_i iid Gaussian(0, sigma) with no
truncation: the realisation has its own tallest summit. y does not matter for a rigid straight
roller and is kept for the record only. Each summit's effective height is e_i = z_i - x_i^2/(2R)
(its height seen by the roller's lowest line); the datum is the tallest effective summit,
z_top = max e_i, so that gap = 0 is the first touch, as in the averaged law. Only summits that can
touch within `depth_max` of the datum are kept (e_i >= z_top - depth_max, default 8 sigma; a
deeper design depth, or a contact that goes deeper, redraws the same realisation with a deeper cut).

Mechanics: the local separation is d(x) = z_top + gap + x^2/(2R) + delta_e(x) and summit i has
approach delta_i = z_i - d(x_i) = e_i - z_top - gap - delta_e(x_i). History is one attached flag
per summit: it attaches when delta_i >= 0 and lets go when delta_i < -Delta (Delta = delta_c, or
the load-controlled stretch 3^(-2/3) delta_c). Trial states apply the rule without committing it
(exactly as the averaged law's effective threshold), `accept` commits it. Attached summits push
with P_JKR(delta_i) on the stable branch. With the half-space on, summit forces are binned into
the cells of a uniform grid (nearest cell), p_j = F_j/(dx l), delta_e = D p
(`continuum.elastic.halfspace.LineHalfSpace`, x_ref = l) and each summit sees its cell's delta_e: the
binning and the sampling are transposes of each other, so force = -d(stored)/d(gap) holds exactly
at equilibrium. The coupled state is a fixed point on the summit forces, warm-started from the last
accepted state (the deflection is femtometres under the paper's roller: 3-4 iterations); it raises
if 20 iterations do not converge.

Energy books: stored = sum over attached summits of U_JKR(delta_i) (+ (1/2) sum_j F_j delta_e,j
with the half-space); dissipated = (number of summits that let go) x (one Fuller-Tabor loop,
U_JKR(-Delta)), booked at `accept`, with a trial state's pending releases reported by
`dissipated`. At the release gap Delta every summit has let go (the tallest effective summit sits
at delta = -Delta there): `on_release` books the loops of those still attached.

Compiled form (rigid substrate only): on a rigid substrate the history rule leaves attached exactly a prefix of
the summits sorted by effective height (those reached, e_i - z_top >= h_min, that have not let go, e_i - z_top
>= gap - Delta), so the deepest accepted gap h_min is the whole history and a contact runs in the compiled
kernel (`continuum.numerics.kernel_laws.LAW_DISCRETE`, the same per-summit closed forms), ~100x faster than the
Python stepper; a state below the kept summits hands the contact back to the Python stepper, which keeps more.

Cost: each force evaluation touches only the prefix of the summits sorted by effective height
that are attached or within reach, so it is O(contacts). The force is discontinuous (a summit
jumps onto the JKR curve at -8/9 P_c and leaves it at -5/9 P_c), so the driver's adaptive
integrator shrinks its steps at each event: cost per impact grows with the number of summits
that touch (docs/discrete.md gives measured numbers).
"""
from __future__ import annotations

import math

import numpy as np

from ..physics import jkr_kernel as jk
from ..reference import jkr as ref
from ..rough.datum import tallest_summit
from ..rough.summits import SummitStatistics
from .roller_base import RoughRollerBase

#: Up to this many attached summits the per-summit laws run in scalar arithmetic
_SCALAR_MAX = 24
#: Summits generated per batch (bounds memory for dense surfaces; part of the realisation's definition).
_CHUNK = 1 << 20


class DiscreteRoughRoller(RoughRollerBase):
    """Roller (radius R, length l, m) on a seeded realisation of GW summits with JKR hysteresis.

    Parameters
    ----------
    stats : SummitStatistics
        sigma (m), summit density n (1/m^2), summit tip radius beta (m).
    work_of_adhesion : float
        Dupre work of adhesion of the summit contacts (J/m^2); 0 gives Hertz summits (no loss).
    summit_e_star : float
        Effective modulus of the summit contacts (Pa).
    radius, length : float
        Roller radius R and length l (m).
    e_star : float
        Effective modulus of the half-space under the summits (Pa).
    seed : int
        Seed of the realisation (numpy Generator).
    detachment : str
        "displacement" (release at -delta_c) or "load" (release at P = -P_c).
    half_space : bool
        Couple the summits to the elastic half-space (eq 17) or treat the substrate as rigid.
    grid_points : int
        Cells of the grid that bins summit forces (half-space, snapshots).
    footprint_half_width : float, optional
        Half-width x_f (m) of the strip holding the realisation; default: the nominal footprint of
        `continuum.rough.datum.tallest_summit`.
    depth_max : float, optional
        Keep summits that touch within this depth (m) below the datum; default 8 sigma.
    summit_law : continuum.rough.branch_laws.SummitLaw, optional
        Tabulated approach and retreat branches of one summit (Maugis-Dugdale, DMT, coated summits) in place of
        the closed-form JKR/Hertz summits: a summit jumps in at delta_in, follows its retreat branch until
        delta_out, and every other summit within reach (delta >= -reach) exerts its approach branch's force (the
        Maugis-Dugdale attraction before contact). JKR is the case delta_in = 0, delta_out = -Delta, reach 0.
    summits : (x, y, z) arrays, optional
        The summits of the strip (m: |x| <= footprint_half_width, 0 <= y <= length, heights) in place of a draw
        from `stats` (e.g. a patch of a height map); the seed then draws nothing.
    heights : optional
        The summit-height distribution of the draw in place of Gaussian(0, sigma): an object whose
        `sample(rng, m)` returns m heights (m) about the summits' mean plane (`continuum.rough.tail`, a map's
        empirical distribution with a fitted extreme-value tail); positions and count are drawn as before.
    """

    name = "rough_roller_discrete_jkr"
    depth_search_name = "discrete rough contact"

    def __init__(self, stats: SummitStatistics, work_of_adhesion: float, summit_e_star: float, radius: float,
                 length: float, e_star: float, *, seed: int, detachment: str = "displacement",
                 half_space: bool = True, grid_points: int = 256, footprint_half_width: float | None = None,
                 depth_max: float | None = None, depth_safety: float = 1.5, coupling_tol: float = 1e-11,
                 max_coupling_iterations: int = 20, summit_law=None, summits=None, heights=None):
        if detachment not in ("displacement", "load"):
            raise ValueError(f"detachment = {detachment!r}: must be 'displacement' or 'load'")
        if not work_of_adhesion >= 0.0:
            raise ValueError(f"work_of_adhesion = {work_of_adhesion!r}: must be >= 0 (J/m^2)")
        self.stats = stats
        self.sigma, self.beta = float(stats.sigma), float(stats.radius)
        self.work_of_adhesion, self.summit_e_star = float(work_of_adhesion), float(summit_e_star)
        self.radius, self.length, self.e_star = float(radius), float(length), float(e_star)
        self.seed = int(seed)
        # the compiled kernel's arrays, rebuilt when the kept-summit array changes (compiled(), _compiled_branches())
        self._compiled_for = None
        self._compiled_tables = None
        self.detachment = detachment
        self.use_half_space = bool(half_space)
        self.n = int(grid_points)
        self.depth_safety = depth_safety
        self.coupling_tol = coupling_tol
        self.max_coupling_iterations = int(max_coupling_iterations)
        self.adhesive = self.work_of_adhesion > 0.0
        b, g, e = self.beta, self.work_of_adhesion, self.summit_e_star
        if self.adhesive:
            self.delta_c = float(ref.critical_approach(b, g, e))
            self.pull_off_force = float(ref.pull_off_force(b, g))
            self.release_stretch = (self.delta_c if detachment == "displacement"
                                    else -float(ref.load_controlled_detach_approach(b, g, e)))
            self.loop_energy = float(ref.loop_area(b, g, e, detachment=detachment))
            self.force_scale = self.pull_off_force
        else:
            self.delta_c = self.pull_off_force = self.release_stretch = self.loop_energy = 0.0
            self.force_scale = 4.0 / 3.0 * e * math.sqrt(b) * self.sigma**1.5
        self.slaw = summit_law
        self._delta_in, self._reach = 0.0, 0.0
        if summit_law is not None:
            self.adhesive = True
            self.name = f"rough_roller_discrete_{summit_law.name}"
            self._delta_in, self._reach = float(summit_law.delta_in), float(summit_law.reach)
            self.touch_gap = self._reach        # the tallest summit's attraction starts here: the contact begins
            self.release_stretch = max(-float(summit_law.delta_out), 0.0)
            self.delta_c = self.release_stretch
            self.pull_off_force = float(summit_law.pull_off_force)
            self.loop_energy = float(summit_law.loop_energy)
            self.force_scale = max(self.pull_off_force, 4.0 / 3.0 * e * math.sqrt(b) * self.sigma**1.5)
        self.end_gap = max(self.release_stretch, self._reach)   # every summit has let go, and is out of reach
        self._hertz_k = 4.0 / 3.0 * e * math.sqrt(b)
        if self.adhesive and summit_law is None:
            self._a0 = float(ref.contact_radius_at_touch(b, g, e))
            self._delta0 = self._a0**2 / b
            self._inv_delta0 = 1.0 / self._delta0
            self._pscale = math.pi * g * b
        self.datum = tallest_summit(self.sigma, stats.density, self.radius, self.length)
        self.footprint_half_width = float(footprint_half_width if footprint_half_width is not None
                                          else self.datum["footprint_half_width"])
        # run-wide diagnostics
        self._start_run_counters(int)
        self.max_depth = 0.0
        self.max_deflection = 0.0
        self.beyond_strip = False
        self.evaluations = 0
        self.deepened = 0
        self.grid_history: list[dict] = []
        self.heights = heights
        self.given_summits = None if summits is None else tuple(np.asarray(a, float) for a in summits)
        self._realise(8.0 * self.sigma if depth_max is None else float(depth_max))
        self.design_depth = 4.0 * self.sigma
        self._set_grid(self.design_depth)

    # ------------------------------------------------------------------ realisation
    def _realise(self, depth_keep: float) -> None:
        """Draw the realisation from the seed (`_draw`), or take the given summits, and keep those with
        e_i >= z_top - depth_keep, sorted by e_i."""
        xf, two_r = self.footprint_half_width, 2.0 * self.radius
        if self.given_summits is not None:
            x, y, z = self.given_summits
            total, raw_top = int(x.size), float(np.max(z, initial=-math.inf))
        else:
            x, y, z, total, raw_top = self._draw(depth_keep)
        if total < 1:
            raise ValueError(f"discrete rough contact: the realisation (seed {self.seed}) holds no summit in the "
                             f"strip |x| <= {xf:.3g} m")
        eff = z - x * x / two_r
        top = float(eff.max())
        k = eff >= top - depth_keep
        order = np.argsort(-eff[k], kind="stable")
        self.sx, self.sy, self.sz = x[k][order], y[k][order], z[k][order]
        self.eff = eff[k][order]                       # descending
        self._neg_eff = -self.eff                      # ascending, for searchsorted
        self.z_top = float(self.eff[0])                # datum: tallest effective summit (m)
        self.z_raw_top = raw_top                       # tallest summit height in the strip (m)
        self.summits_in_strip = total
        self.depth_keep = depth_keep
        # deepest approach the strip covers: beyond it, summits outside |x| <= x_f as tall as the
        # realisation's tallest could touch
        self.strip_depth = xf * xf / two_r + self.z_top - raw_top
        self.attached = np.zeros(self.eff.size, bool)

    def _draw(self, depth_keep: float):
        """(x, y, z, summits in the strip, tallest z) of the seed's draw from the statistics, keeping a superset of
        the summits with e_i >= max e - depth_keep. Batches of _CHUNK summits (x, y, z drawn in that order per
        batch) keep memory bounded; the running maximum of e_i only grows, so each batch's filter keeps a superset."""
        rng = np.random.default_rng(self.seed)
        xf, l, two_r = self.footprint_half_width, self.length, 2.0 * self.radius
        total = int(rng.poisson(self.stats.density * 2.0 * xf * l))
        keep_x, keep_y, keep_z = [], [], []
        top, raw_top = -math.inf, -math.inf
        left = total
        while left > 0:
            m = min(left, _CHUNK)
            left -= m
            x = rng.uniform(-xf, xf, m)
            y = rng.uniform(0.0, l, m)
            z = rng.normal(0.0, self.sigma, m) if self.heights is None else self.heights.sample(rng, m)
            eff = z - x * x / two_r
            top = max(top, float(eff.max()))
            raw_top = max(raw_top, float(z.max()))
            k = eff >= top - depth_keep
            keep_x.append(x[k])
            keep_y.append(y[k])
            keep_z.append(z[k])
        if total < 1:
            return np.zeros(0), np.zeros(0), np.zeros(0), 0, raw_top
        return np.concatenate(keep_x), np.concatenate(keep_y), np.concatenate(keep_z), total, raw_top

    def _deepen(self, depth_keep: float) -> None:
        """Keep more of the same realisation (mid-contact): the kept summits come first in the same
        order, so the history and the warm start extend with unattached, unloaded summits."""
        n_old = self.eff.size
        attached = self.attached
        self._realise(depth_keep)
        self.attached[:n_old] = attached
        self._bin(self._half)
        self.deepened += 1

    @property
    def summits_kept(self) -> int:
        return int(self.eff.size)

    # ------------------------------------------------------------------ per-summit laws
    def _laws(self, delta: np.ndarray) -> dict:
        """Per-summit JKR (or Hertz) quantities at approaches `delta` (m) on the stable branch.

        JKR in s = sqrt(a/a0) (`continuum.physics.jkr_kernel`): delta/delta0 = s^4 - s, solved in
        closed form by the kernel's unchecked root (the reference's Ferrari/Cardano route, without
        its argument checks (the history rule never asks for delta < -Delta); then P, U, dP/d delta
        and a are explicit in s. Returns arrays "force" (N) and, lazily via `_energy` etc., the rest.
        """
        if self.slaw is not None:
            return {"delta": delta, "force": self.slaw.force(delta, "retreat")}
        if not self.adhesive:
            dp = np.maximum(delta, 0.0)
            return {"delta": delta, "force": self._hertz_k * dp * np.sqrt(dp)}
        if delta.size <= _SCALAR_MAX:
            return self._laws_scalar(delta)
        d = delta * self._inv_delta0
        s = jk.stable_root(d)                             # clamps d to the fold in place
        return {"delta": delta, "d": d, "s": s, "force": jk.stable_force_in_place(s, self._pscale)}

    def _laws_scalar(self, delta: np.ndarray) -> dict:
        """_laws for a few summits: the same formulas in scalar arithmetic (numpy calls cost more here)."""
        inv, ps = self._inv_delta0, self._pscale
        ds, ss, fs = [], [], []
        for dl in delta.tolist():
            d, s = jk.stable_root_scalar(dl * inv)
            s3 = s * s * s
            ds.append(d)
            ss.append(s)
            fs.append(ps * s3 * (8.0 / 3.0 * s3 - 4.0))
        return {"delta": delta, "d": np.array(ds), "s": np.array(ss), "force": np.array(fs)}

    def _energy(self, q: dict) -> np.ndarray:
        """Stored energy U(delta) (J) along the stable branch, U(0) = 0 (the kernel's closed form)."""
        if self.slaw is not None:
            return self.slaw.energy(q["delta"], "retreat")
        if not self.adhesive:
            dp = np.maximum(q["delta"], 0.0)
            return 0.4 * self._hertz_k * dp * dp * np.sqrt(dp)
        return jk.energy_of_s(q["d"], q["s"], self._pscale * self._delta0)

    def _stiffness(self, q: dict) -> np.ndarray:
        """dP/d delta (N/m); -inf exactly at the fold."""
        if self.slaw is not None:           # central difference on the tabulated retreat branch
            h = 1e-6 * self.sigma
            return (self.slaw.force(q["delta"] + h, "retreat") - self.slaw.force(q["delta"] - h, "retreat")) / (2 * h)
        if not self.adhesive:
            return 1.5 * self._hertz_k * np.sqrt(np.maximum(q["delta"], 0.0))
        s = q["s"]
        s3 = s * s * s
        den = 4.0 * s3 - 1.0
        with np.errstate(divide="ignore", invalid="ignore"):
            k = jk.stiffness_of_s(s, s3, self._pscale * self._inv_delta0)
        return np.where(den > 0.0, k, -np.inf)

    def _area(self, q: dict) -> np.ndarray:
        """Real contact area pi a^2 (m^2) of each summit."""
        if self.slaw is not None:
            return math.pi * self.slaw.contact_radius(q["delta"], "retreat") ** 2
        if not self.adhesive:
            return math.pi * self.beta * np.maximum(q["delta"], 0.0)
        a = self._a0 * q["s"] ** 2
        return math.pi * a * a

    # ------------------------------------------------------------------ grid and state
    def _set_grid(self, depth: float) -> None:
        """Grid over the summits reachable at `depth` below the datum (plus twice the release stretch)."""
        reach = self._count_above(self.z_top - depth - 2.0 * self.release_stretch)
        half = max(float(np.max(np.abs(self.sx[:max(reach, 1)]))),
                   math.sqrt(2.0 * self.radius * (depth + 2.0 * self.release_stretch)))
        half = min(1.05 * half, self.footprint_half_width)
        self._line_grid(half)
        self._bin(half)
        self.reset()

    def _bin(self, half: float) -> None:
        """Cell of every kept summit on the grid |x| <= half (summits outside go to the edge cells)."""
        self._half = half
        raw = np.floor((self.sx + half) / self.dx).astype(np.intp)
        self.cell = np.clip(raw, 0, self.n - 1)
        self.outside = raw != self.cell                    # summits clamped into an edge cell

    def reset(self) -> None:
        self.attached[:] = False
        self.k_att = 0                          # 1 + largest index of an attached summit
        self.detached = 0                       # summits that let go in this contact
        self.f_last = np.zeros(0)               # summit forces of the last accepted state (prefix)
        self._cache_gap = None

    def _count_above(self, level: float) -> int:
        """Number of kept summits with effective height >= level."""
        return int(np.searchsorted(self._neg_eff, -level, side="right"))

    def size_for(self, depth: float, speed: float) -> None:
        """Size the grid (and, if needed, the kept set) for a design depth (m), at least twice the release
        stretch."""
        depth = max(depth, 2.0 * self.release_stretch)
        if depth + 2.0 * self.release_stretch > self.depth_keep:
            self._realise(2.0 * (depth + 2.0 * self.release_stretch))
        self.design_depth = depth
        self._set_grid(depth)
        self._record_grid(depth, speed)

    @property
    def sized_depth(self) -> float:
        return self.design_depth

    def approach_force(self, gap: float) -> float:
        """Force (N) of a monotonic first approach to `gap` on a rigid substrate (grid sizing)."""
        k = self._count_above(self.z_top + gap - self._reach)
        if k == 0:
            return 0.0
        if self.slaw is not None:
            return float(np.sum(self.slaw.force(self.eff[:k] - self.z_top - gap, "approach")))
        return float(np.sum(self._laws(self.eff[:k] - self.z_top - gap)["force"]))

    def approach_forces(self, depths: np.ndarray) -> np.ndarray:
        """First-approach forces (N) at `depths` (m below the datum), one summit sum each.

        A tabulated summit law interpolates every depth's summits in one call and sums the rows with the summits
        out of reach zeroed (the same terms as `approach_force`, summed in another order: equal to rounding);
        closed-form summits go depth by depth."""
        depths = np.asarray(depths, float)
        if self.slaw is None or depths.size == 0:
            return np.array([self.approach_force(-d) for d in depths])
        counts = np.searchsorted(self._neg_eff, -(self.z_top - depths - self._reach), side="right")
        k_max = int(counts.max())
        if k_max == 0:
            return np.zeros(depths.size)
        delta = (self.eff[:k_max] - self.z_top)[None, :] + depths[:, None]       # approach_force's, rounding too
        f = self.slaw.force(delta, "approach")
        f[np.arange(k_max)[None, :] >= counts[:, None]] = 0.0
        return f.sum(axis=1)

    def _summits_at(self, gap: float, de_lo: float, de_of=None):
        """Trial state over the prefix of summits that are attached or within reach.

        `de_lo` is a lower bound (m) of the half-space deflection anywhere; `de_of(k)` returns the
        deflection at the first k summits (None: rigid). The history rule is applied, not committed.
        Returns (k, delta, attached_eff, laws of the attached, force, deflection at the summits).
        """
        base = self.z_top + gap
        if base + min(de_lo, 0.0) < self.z_top - self.depth_keep:
            self._deepen(2.0 * (self.z_top - base - min(de_lo, 0.0)))
        k = max(self.k_att, self._count_above(base + min(de_lo, 0.0) - self._reach))
        if de_of is None:
            de = None
            delta = self.eff[:k] - base
        else:
            de = de_of(k)
            delta = self.eff[:k] - base - de
        att = (self.attached[:k] | (delta >= self._delta_in)) & (delta >= -self.release_stretch)
        q = self._laws(delta[att])
        force = np.zeros(k)
        force[att] = q["force"]
        if self.slaw is not None:           # summits in reach, not jumped in: the approach branch
            free = ~att & (delta >= -self._reach)
            q["free_delta"] = delta[free]
            force[free] = self.slaw.force(q["free_delta"], "approach")
        return k, delta, att, q, force, de

    def _evaluate(self, gap: float) -> dict:
        """Trial state at `gap` with the stored history (`_state` caches it on the gap)."""
        self.evaluations += 1
        if self.hs is None:
            k, delta, att, q, force, de = self._summits_at(gap, 0.0)
        else:
            k, delta, att, q, force, de = self._coupled(gap)
        return {"k": k, "delta": delta, "att": att, "q": q, "force": force, "de": de}

    def _deflection_at(self, k: int, force_prev: np.ndarray) -> np.ndarray:
        """Half-space deflection (m) at the cells of the first k summits under summit loads `force_prev`
        (forces of the first force_prev.size summits).

        delta_e = D p with p_j = F_j/(dx l) binned by cell: a direct sum over the loaded summits
        when they are few, the FFT convolution of the grid otherwise (same numbers to rounding).
        """
        loaded = np.flatnonzero(force_prev)
        cells = self.cell[:k]
        if loaded.size == 0:
            return np.zeros(k)
        scale = 1.0 / (self.dx * self.length)
        if k * loaded.size <= 40000:
            dist = np.abs(cells[:, None] - self.cell[loaded][None, :])
            return (self.hs.coefficients[dist] @ force_prev[loaded]) * scale
        p = np.bincount(self.cell[loaded], weights=force_prev[loaded], minlength=self.n) * scale
        return self.hs.displacement(p)[cells]

    def _coupled(self, gap: float):
        """Warm-started fixed point F <- F_JKR(delta(D bin(F))) at the summits; raises after
        max_coupling_iterations.

        Starts from the summit forces of the last accepted state. The bound on the deflection that
        sizes the prefix uses D_0 >= D_k > 0 (log kernel within x_ref = l): |delta_e| <= D_0 sum|p|.
        """
        f_prev = self.f_last
        d0 = self.hs.coefficients[0] / (self.dx * self.length)
        change = math.inf
        for _ in range(self.max_coupling_iterations):
            de_lo = -d0 * float(np.sum(np.abs(f_prev)))

            def de_of(k, f=f_prev):
                return self._deflection_at(k, f)

            k, delta, att, q, force, de = self._summits_at(gap, de_lo, de_of)
            m = min(k, f_prev.size)
            change = max(float(np.max(np.abs(force[:m] - f_prev[:m]), initial=0.0)),
                         float(np.max(np.abs(force[m:]), initial=0.0)), float(np.max(np.abs(f_prev[m:]), initial=0.0)))
            f_prev = force
            if change <= self.coupling_tol * max(self.force_scale, float(np.max(np.abs(force), initial=0.0))):
                return k, delta, att, q, force, de
        raise RuntimeError(f"discrete rough contact: the summit-force / half-space fixed point did not converge in "
                           f"{self.max_coupling_iterations} iterations at gap {gap:.6g} m (last force change "
                           f"{change:.3g} N against {self.force_scale:.3g} N): the coupling is too strong for this "
                           "solver; run with physics.half_space = 'off' or the averaged mode")

    def _grid(self, s: dict):
        """(pressure p (Pa), deflection delta_e (m)) on the grid for a state (binned summit forces)."""
        p = np.bincount(self.cell[:s["k"]], weights=s["force"], minlength=self.n) / (self.dx * self.length)
        de = self.hs.displacement(p) if self.hs is not None else np.zeros(self.n)
        return p, de

    # ------------------------------------------------------------------ ContactLaw
    def force(self, gap):
        return float(np.sum(self._state(gap)["force"]))

    def stiffness(self, gap):
        return float(np.sum(self._stiffness(self._state(gap)["q"])))

    def stored_energy(self, gap):
        s = self._state(gap)
        summits = float(np.sum(self._energy(s["q"])))
        if "free_delta" in s["q"]:
            summits += float(np.sum(self.slaw.energy(s["q"]["free_delta"], "approach")))
        elastic = 0.5 * float(np.dot(s["force"], s["de"])) if s["de"] is not None else 0.0
        return summits + elastic

    def _pending(self, s) -> int:
        """Summits attached in the stored history that the trial state lets go."""
        return int(np.count_nonzero(self.attached[:s["k"]] & ~s["att"]))

    def dissipated(self, gap):
        return (self.detached + self._pending(self._state(gap))) * self.loop_energy

    def accept(self, gap):
        s = self._state(gap)
        k, att = s["k"], s["att"]
        self.detached += self._pending(s)
        self.attached[:k] = att
        idx = np.flatnonzero(att)
        self.k_att = int(idx[-1]) + 1 if idx.size else 0
        self.f_last = s["force"]
        self._cache_gap = None
        self.max_contacts = max(self.max_contacts, int(idx.size))
        self.max_depth = max(self.max_depth, float(-gap))
        if idx.size and np.any(self.outside[idx]):
            self.edge_touched = True
        if -gap > self.strip_depth:
            self.beyond_strip = True
        if idx.size:
            p, de = self._grid(s)
            self.max_deflection = max(self.max_deflection, float(np.max(np.abs(de))))
            self.max_pressure = max(self.max_pressure, float(np.max(p)))

    def compiled(self, t0: float):
        """The kept summits as the compiled kernel reads them (`continuum.numerics.kernel_laws.LAW_DISCRETE`); None
        with the half-space on (its coupled fixed point runs in Python)."""
        from ..numerics import kernel_laws as kl
        from ..numerics.compiled_contact import EMPTY_TABLES, CompiledLaw

        if self.use_half_space:
            return None
        if self.slaw is not None:
            return self._compiled_branches()
        if self._compiled_for is not self.eff:
            P = np.zeros(kl.DISCRETE_PARAMS)
            P[kl.P_D_END_GAP], P[kl.P_D_RELEASE], P[kl.P_D_LOOP] = self.end_gap, self.release_stretch, self.loop_energy
            P[kl.P_D_HERTZ_K], P[kl.P_D_ADHESIVE] = self._hertz_k, 1.0 if self.adhesive else 0.0
            if self.adhesive:
                P[kl.P_D_INV_DELTA0], P[kl.P_D_PSCALE] = self._inv_delta0, self._pscale
                P[kl.P_D_ESCALE] = self._pscale * self._delta0
            P[kl.P_D_LOWEST] = -self.depth_keep
            self._compiled_tables = (P, (np.ascontiguousarray(self.eff - self.z_top),) + EMPTY_TABLES[1:])
            self._compiled_for = self.eff
        P, T = self._compiled_tables
        return CompiledLaw(kl.LAW_DISCRETE, P, T, np.array([math.inf, 0.0, 0.0, 0.0, 0.0]))

    def _compiled_branches(self):
        """`continuum.numerics.kernel_laws.LAW_DISCRETE_BRANCH`: the kept summits and the summit law's two
        branches."""
        from ..numerics import kernel_laws as kl
        from ..numerics.compiled_contact import EMPTY_TABLES, CompiledLaw

        if self._compiled_for is not self.eff:
            P = np.zeros(kl.BRANCH_PARAMS)
            P[kl.P_B_END_GAP], P[kl.P_B_IN], P[kl.P_B_OUT] = self.end_gap, self._delta_in, -self.release_stretch
            P[kl.P_B_REACH], P[kl.P_B_LOOP], P[kl.P_B_LOWEST] = self._reach, self.loop_energy, -self.depth_keep
            a, r = self.slaw.approach, self.slaw.retreat
            tables = tuple(np.ascontiguousarray(x, float) for x in
                           (self.eff - self.z_top, a.delta, a.force, a.energy, r.delta, r.force, r.energy))
            self._compiled_tables = (P, tables + EMPTY_TABLES[7:])
            self._compiled_for = self.eff
        P, T = self._compiled_tables
        return CompiledLaw(kl.LAW_DISCRETE_BRANCH, P, T, np.array([math.inf, 0.0, 0.0, 0.0, 0.0]))

    def compiled_commit(self, state, last_accept: float) -> None:
        """Take back a compiled contact: the summits reached at its deepest gap h_min are the history (the detach
        rule is applied to them at any later gap), and the run-wide diagnostics."""
        h_min = float(state[0])
        if not math.isfinite(h_min):
            return
        reached = int(state[1])
        self.attached[:] = False
        self.attached[:reached] = True
        self.k_att = reached
        self._cache_gap = None
        self.max_contacts = max(self.max_contacts, int(state[2]))
        self.max_depth = max(self.max_depth, -h_min)
        if -h_min > self.strip_depth:
            self.beyond_strip = True
        if reached and np.any(self.outside[:reached]):
            self.edge_touched = True

    def on_release(self):
        """Every summit still attached lets go at the release gap: book their loops with the others'."""
        self.detached += int(np.count_nonzero(self.attached))
        self.attached[:] = False
        self.k_att = 0
        self._cache_gap = None
        return self.detached * self.loop_energy

    def snapshot(self, gap: float) -> dict:
        """Binned pressure, deflection and gap across the grid at `gap`, plus the summits in reach; SI."""
        s = self._state(gap)
        k, delta, att, force = s["k"], s["delta"], s["att"], s["force"]
        p, de = self._grid(s)
        cell_area = self.dx * self.length
        cells = self.cell[:k]
        area = np.zeros(k)
        area[att] = self._area(s["q"])
        return {"x": self.x.copy(), "pressure": p,
                "compressive": np.bincount(cells, weights=np.maximum(force, 0.0), minlength=self.n) / cell_area,
                "tensile": np.bincount(cells, weights=np.minimum(force, 0.0), minlength=self.n) / cell_area,
                "deflection": de, "separation": gap + self.x**2 / (2.0 * self.radius) + de,
                "contact_fraction": np.bincount(cells, weights=area, minlength=self.n) / cell_area,
                "summits": {"x": self.sx[:k].copy(), "y": self.sy[:k].copy(), "z": self.sz[:k].copy(),
                            "approach": delta.copy(), "attached": att.copy(), "force": force.copy()}}

    def diagnostics(self):
        return {"mode": "discrete", "seed": self.seed, "max_contacts": self.max_contacts,
                "summits_in_strip": self.summits_in_strip, "summits_kept": self.summits_kept,
                "kept_depth": self.depth_keep, "kept_set_deepened": self.deepened,
                "tallest_summit": {"effective_m": self.z_top, "effective_sigma": self.z_top / self.sigma,
                                   "height_m": self.z_raw_top, "height_sigma": self.z_raw_top / self.sigma,
                                   "expected_z_max_sigma": self.datum["z_max"]},
                "max_depth": self.max_depth, "strip_depth": self.strip_depth, "beyond_strip": self.beyond_strip,
                "edge_touched": self.edge_touched, "max_deflection": self.max_deflection,
                "max_nominal_pressure": self.max_pressure, "force_evaluations": self.evaluations,
                **self._grid_record()}

    def describe(self):
        source = ("seeded realisation of GW (1966) summits, each JKR + Fuller-Tabor hysteresis; paper eqs 9-17"
                  if self.slaw is None else f"seeded realisation of GW (1966) summits, each on the tabulated branches "
                  f"of a {self.slaw.name} summit (continuum.rough.branch_laws)")
        return {"name": self.name, "mode": "discrete", "source": source,
                "radius": self.radius, "length": self.length, "e_star": self.e_star,
                "half_space": self.use_half_space, "grid_points": self.n, "seed": self.seed,
                "sigma": self.sigma, "summit_density": self.stats.density, "summit_radius": self.beta,
                "summit_e_star": self.summit_e_star, "work_of_adhesion": self.work_of_adhesion,
                "detachment": self.detachment, "z_max": self.z_top,
                "footprint_half_width": self.footprint_half_width, "summits_in_strip": self.summits_in_strip,
                "summits_kept": self.summits_kept, "kept_depth": self.depth_keep,
                "delta_c": self.delta_c, "release_stretch": self.release_stretch,
                "pull_off_force_per_summit": self.pull_off_force, "loop_energy_per_summit": self.loop_energy}
