"""One summit's adhesive law under displacement control: the branches it actually follows.

A summit of tip radius beta (m) is driven by its approach delta (m; < 0 = stretched / separated),
set by the separation of the surfaces: displacement control. Each model gives its full equilibrium
curve P(s), delta(s), loaded radius(s), with s running from the free end (no attraction yet) along
growing contact. Under displacement control a state is stable where delta increases with s
(Maugis 2000 §5.3: dP/d(delta) finite and the contact grows as the surfaces are pushed together);
where delta(s) turns back (a fold) the summit jumps at constant delta to another stable part, or to
the free state. Following the folds:

* approach branch A(delta): from the free state, delta increasing: follow stable parts; at the end
  of one (a maximum of delta(s)) jump forward to the next stable part at that delta;
* retreat branch R(delta): from deep contact, delta decreasing: follow stable parts back to their
  start (a minimum of delta(s)) and jump back to the nearest earlier stable part at that delta,
  or to the free state.

delta_in is the largest delta at which A jumps, delta_out the smallest at which R jumps; A and R
differ only between them (one hysteresis loop for JKR and Maugis-Dugdale; none for DMT). The
stored energy is U = int P d(delta) along the path taken (free summit: 0):
U_A(delta) along A, U_R(delta) = U_A(delta_in) + int_{delta_in}^{delta} P_R, and the energy lost per
approach-retreat cycle is loop_energy = U_R(delta_out) - U_A(delta_out).

Models (SI; E* Johnson's contact modulus, dgamma Dupre's work of adhesion)
--------------------------------------------------------------------------
* JKR (Johnson, Kendall & Roberts 1971): P = 4E*a^3/(3 beta) - sqrt(8 pi dgamma E* a^3),
  delta = a^2/beta - sqrt(2 pi dgamma a/E*), s = a. A jumps in at delta = 0 to P = -8/9 P_c,
  R jumps out at -delta_c: the Fuller-Tabor loop 0.9355 P_c delta_c (``continuum.reference.jkr``).
* DMT (Derjaguin, Muller & Toporov 1975): P = (4/3)E* beta^{1/2} delta^{3/2} - 2 pi beta dgamma in
  contact, 0 out of contact; the force jumps at delta = 0 both ways: no loop, U = Hertz - 2 pi beta
  dgamma delta.
* Maugis-Dugdale (Maugis 1992; Johnson & Greenwood 1997): a constant tension sigma0 acts where the
  gap is below h0 = dgamma/sigma0; sigma0 = 1.03 dgamma/z0 (Johnson & Greenwood's match to the
  Lennard-Jones law, lambda = 1.16 mu). The curve has two parts:
  - non-contact (a = 0): tension sigma0 on a circle of radius c pulls the surfaces together by
    2 sigma0 c/E* at the centre and (4/pi) sigma0 c/E* at r = c (uniform pressure on a circle,
    Johnson, Contact Mechanics §3.2, both bodies); the gap at r = c is h0, so
    delta = c^2/(2 beta) - (4/pi)(sigma0/E*) c - h0, P = -pi sigma0 c^2, valid while the central gap
    -delta - 2 sigma0 c/E* >= 0, i.e. c <= c_e; it starts at delta = -h0 (the reach);
  - contact (a > 0): Maugis' parametric solution (``continuum.reference.maugis``), whose a -> 0 end
    meets the non-contact part at c_e exactly (tested: c, delta and P agree to 1e-9).
  Folds of this curve give the jumps: for large lambda the summit snaps into contact at
  delta -> 0 and out at -> -delta_c (JKR); for small lambda the curve has no fold and no loop (DMT).
* A SAM as a compliant layer on each summit does not enter here: the laws take the coated summits' contact
  modulus E* (``continuum.physics.coated``, ``continuum.model.regime.coated_summits``).

Cost: building a Maugis-Dugdale law solves Maugis' equation once at each of ~2000 contact radii (compiled,
`continuum.reference.maugis_kernel`: a few ms); JKR and DMT are closed form. Branches are tabulated on ~4000
points and evaluated by linear interpolation (measured error against the closed forms:
tests/continuum/test_branch_laws.py).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..reference import jkr as jkr_ref
from ..reference import maugis as md_ref

#: Johnson & Greenwood (1997): Dugdale stress matching the Lennard-Jones law's, sigma0 = 1.03 dgamma/z0.
DUGDALE_FACTOR = 1.03


@dataclass
class Branch:
    """A branch tabulated on strictly increasing delta (m): force P (N), loaded radius a (m), energy U (J)."""

    delta: np.ndarray
    force: np.ndarray
    radius: np.ndarray
    energy: np.ndarray
    contact: np.ndarray
    """True contact radius (m): 0 on non-contact (cohesive-zone) states."""

    def __call__(self, what: str, delta):
        return np.interp(np.asarray(delta, float), self.delta, getattr(self, what))


def _increasing_runs(delta: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges [i0, i1] over which delta increases strictly (stable under displacement control)."""
    up = np.diff(delta) > 0
    runs, i = [], 0
    n = up.size
    while i < n:
        if up[i]:
            j = i
            while j < n and up[j]:
                j += 1
            runs.append((i, j))
            i = j
        else:
            i += 1
    return runs


def _locate(delta, run, value):
    """Fractional index in run (i0..i1) where delta = value (delta increasing on the run), or None."""
    i0, i1 = run
    if not delta[i0] <= value <= delta[i1]:
        return None
    k = int(np.searchsorted(delta[i0:i1 + 1], value)) + i0
    k = min(max(k, i0 + 1), i1)
    f = (value - delta[k - 1]) / (delta[k] - delta[k - 1])
    return k - 1 + f


def _interp_at(arr, pos):
    k = int(math.floor(pos))
    f = pos - k
    if f == 0.0 or k + 1 >= arr.size:
        return arr[min(k, arr.size - 1)]
    return arr[k] * (1 - f) + arr[k + 1] * f


def _piece(delta, force, radius, run, start_pos, end_pos):
    """Points of `run` from fractional position start_pos to end_pos (start < end), interpolated ends."""
    k0, k1 = int(math.floor(start_pos)) + 1, int(math.ceil(end_pos)) - 1
    idx = np.arange(k0, k1 + 1)
    d = np.concatenate([[_interp_at(delta, start_pos)], delta[idx], [_interp_at(delta, end_pos)]])
    p = np.concatenate([[_interp_at(force, start_pos)], force[idx], [_interp_at(force, end_pos)]])
    a = np.concatenate([[_interp_at(radius, start_pos)], radius[idx], [_interp_at(radius, end_pos)]])
    keep = np.concatenate([[True], np.diff(d) > 0])
    return d[keep], p[keep], a[keep]


def _first_run_at(delta, runs, value, admissible):
    """(run, fractional position) of the first run in `runs` that `admissible` accepts and that holds
    delta = value, or None."""
    for r in runs:
        if admissible(r):
            pos = _locate(delta, r, value)
            if pos is not None:
                return r, pos
    return None


def follow_folds(delta, force, radius):
    """Approach and retreat paths of a curve (arrays along s, s = 0 the free end with P = 0).

    Returns (approach pieces, approach jump deltas, retreat pieces, retreat jump deltas); a piece is
    (delta, force, radius) with delta increasing. The free state (P = 0) holds below delta[0]. A
    retreat that runs back continuously to the free end (s = 0, P = 0) records its end as the
    release point without a force jump (DMT).
    """
    runs = _increasing_runs(delta)
    if not runs:
        raise ValueError("the equilibrium curve has no stable part")
    last = delta.size - 1
    # ---- approach: from the free end, delta increasing
    pieces, jumps = [], []
    value, after, first = delta[0], 0, True
    while True:
        hit = _first_run_at(delta, runs, value, lambda q, after=after: q[0] >= after)
        if hit is None:
            break
        r, pos = hit
        if not (first and r[0] == 0 and pos == 0.0):
            jumps.append(float(value))
        first = False
        if pos < r[1]:
            pieces.append(_piece(delta, force, radius, r, pos, float(r[1])))
        value, after = delta[r[1]], r[1]
        if r[1] == last:
            break
    # ---- retreat: from the end, delta decreasing
    rpieces, rjumps = [], []
    r, end = runs[-1], float(runs[-1][1])
    while True:
        if end > r[0]:
            rpieces.append(_piece(delta, force, radius, r, float(r[0]), end))
        value = delta[r[0]]
        rjumps.append(float(value))
        back = _first_run_at(delta, runs[::-1], value, lambda q, start=r[0]: q[1] <= start)
        if back is None:
            break
        r, end = back
    return pieces, jumps, rpieces[::-1], rjumps


def _concat(pieces):
    d = np.concatenate([p[0] for p in pieces])
    f = np.concatenate([p[1] for p in pieces])
    a = np.concatenate([p[2] for p in pieces])
    # a jump leaves two points at one delta: separate them by a rounding-level step so that
    # interpolation is one-sided (left value below the jump, right value above)
    # (only where delta does not increase, and the points after one that a step pushes past: the left-to-right
    # pass over every point, visiting only those that can change)
    for i in np.flatnonzero(d[1:] <= d[:-1]) + 1:
        while i < d.size and d[i] <= d[i - 1]:
            d[i] = np.nextafter(d[i - 1], np.inf) + 1e-15 * abs(d[i - 1])
            i += 1
    return d, f, a


def _cumulative_work(d, f):
    return np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(d))])


class SummitLaw:
    """Approach and retreat branches of one summit, with jump points, reach and loop energy (SI).

    Build with `jkr_law`, `dmt_law`, `maugis_dugdale_law` (or `make_summit_law`). force/energy/
    radius(delta, branch) with branch 'approach' or 'retreat' are vectorised.
    """

    def __init__(self, name: str, radius: float, work_of_adhesion: float, e_star: float, curve, *,
                 delta_max: float, extra: dict | None = None):
        self.name, self.radius_tip = name, radius
        self.work_of_adhesion, self.e_star = work_of_adhesion, e_star
        d, f, a, ac = curve
        pieces, jumps, rpieces, rjumps = follow_folds(d, f, a + 1j * ac)   # carry both radii together
        free = float(d[0])
        lo = free - 1e-3 * max(abs(free), 1e-9)        # the free summit below the curve's free end
        da, fa, aa = _concat([(np.array([lo, free]), np.zeros(2), np.zeros(2, complex)), *pieces])
        dr, fr, ar = _concat(rpieces)
        self.delta_in = max(jumps) if jumps else free
        self.delta_out = min(rjumps) if rjumps else free
        self.reach = max(-float(free), 0.0)
        ua = _cumulative_work(da, fa)
        self.approach = Branch(da, fa, aa.real, ua, aa.imag)
        # retreat: below delta_out the summit is free and back on A
        u_in = float(np.interp(self.delta_in, da, ua))
        ur = _cumulative_work(dr, fr)
        ur = ur - float(np.interp(self.delta_in, dr, ur)) + u_in
        self.retreat = Branch(dr, fr, ar.real, ur, ar.imag)
        self.loop_energy = float(np.interp(self.delta_out, dr, ur) - np.interp(self.delta_out, da, ua))
        self.pull_off_force = float(-np.min(fr))              # largest tension on R (displacement control)
        self.load_pull_off_force = float(-min(np.min(fr), np.min(fa)))
        self.delta_max = delta_max
        self.extra = extra or {}
        if da[-1] < delta_max or dr[-1] < delta_max:
            raise ValueError(f"{name} summit law tabulated only to {min(da[-1], dr[-1]):.3g} m < {delta_max:.3g} m")

    def _branch(self, branch):
        if branch == "approach":
            return self.approach
        if branch == "retreat":
            return self.retreat
        raise ValueError(f"branch = {branch!r}: 'approach' or 'retreat'")

    def force(self, delta, branch="retreat"):
        """Force P (N, + compressive) at approach delta (m) on a branch."""
        return self._branch(branch)("force", delta)

    def energy(self, delta, branch="retreat"):
        """Stored energy U (J) on a branch, zero for the free summit."""
        return self._branch(branch)("energy", delta)

    def contact_radius(self, delta, branch="retreat"):
        """True contact radius (m); 0 out of contact."""
        return self._branch(branch)("contact", delta)

    def describe(self) -> dict:
        return {"name": self.name, "radius": self.radius_tip, "work_of_adhesion": self.work_of_adhesion,
                "e_star": self.e_star, "delta_in": self.delta_in, "delta_out": self.delta_out, "reach": self.reach,
                "loop_energy": self.loop_energy, "pull_off_force_displacement": self.pull_off_force,
                "pull_off_force_load": self.load_pull_off_force, **self.extra,
                "source": "continuum/rough/branch_laws.py (fold-following of the full equilibrium curve)"}


# ----------------------------------------------------------------------------- curves
def _radii(a_max, a_min, n):
    u = np.linspace(0.0, 1.0, n)
    return a_min + (a_max - a_min) * u**2


def jkr_law(beta, w, e_star, *, delta_max, n=4000) -> SummitLaw:
    """JKR summit with Fuller-Tabor jumps (displacement-controlled release)."""
    a_touch = float(jkr_ref.contact_radius_at_touch(beta, w, e_star))
    a_max = math.sqrt(beta * (delta_max + 2 * float(jkr_ref.critical_approach(beta, w, e_star)))) * 1.2 + 2 * a_touch
    a = _radii(a_max, 0.0, n)
    p = np.asarray(jkr_ref.force_from_radius(a, beta, w, e_star), float)
    d = np.asarray(jkr_ref.approach_from_radius(a, beta, w, e_star), float)
    return SummitLaw("jkr", beta, w, e_star, (d, p, a, a), delta_max=delta_max)


def dmt_law(beta, w, e_star, *, delta_max, n=4000) -> SummitLaw:
    """DMT summit: Hertz minus 2 pi beta dgamma in contact, no loop."""
    a_max = math.sqrt(beta * delta_max) * 1.2
    a = _radii(a_max, 0.0, n)
    p_h = 4.0 * e_star * a**3 / (3.0 * beta)
    d = a * a / beta
    p = p_h - 2.0 * math.pi * beta * w
    # the free state holds for delta < 0; the curve starts at touch with the adhesive force at once
    d = np.concatenate([[0.0], d])
    p = np.concatenate([[0.0], p])
    a = np.concatenate([[0.0], a])
    d[1] = np.nextafter(0.0, 1.0)
    return SummitLaw("dmt", beta, w, e_star, (d, p, a, a), delta_max=delta_max)


def maugis_dugdale_law(beta, w, e_star, z0, *, delta_max, n_contact=2000, n_free=400) -> SummitLaw:
    """Maugis-Dugdale summit (sigma0 = 1.03 dgamma/z0) with non-contact and contact parts."""
    sigma0 = DUGDALE_FACTOR * w / z0
    h0 = w / sigma0
    lam = float(md_ref.md_parameter(beta, w, e_star, sigma0))
    a_s, p_s, d_s = (float(x) for x in md_ref.md_scales(beta, w, e_star))
    k = sigma0 / e_star
    c_e = beta * (-(2 - 4 / math.pi) * k + math.sqrt((2 - 4 / math.pi) ** 2 * k * k + 2 * h0 / beta))
    c = np.linspace(0.0, c_e, n_free)
    d_nc = c * c / (2 * beta) - 4 / math.pi * k * c - h0
    p_nc = -math.pi * sigma0 * c * c
    a_top = math.sqrt((delta_max + 4 * d_s) / d_s) * 1.2 + 2.0          # A with Dbar ~ A^2 beyond delta_max
    A = _radii(a_top, 1e-6, n_contact)
    pbar, dbar, m = md_ref.md_solution(A, lam)
    m = np.asarray(m, float)
    p_c = np.asarray(pbar, float) * p_s
    cz = m * A * a_s
    d_c = np.asarray(dbar, float) * d_s
    d = np.concatenate([d_nc, d_c])
    p = np.concatenate([p_nc, p_c])
    a = np.concatenate([c, cz])
    ac = np.concatenate([np.zeros_like(c), A * a_s])
    return SummitLaw("maugis_dugdale", beta, w, e_star, (d, p, a, ac), delta_max=delta_max,
                     extra={"maugis_lambda": lam, "dugdale_stress": sigma0, "dugdale_range_h0": h0, "z0": z0})


def _build_summit_law(name: str, beta: float, w: float, e_star: float, *, z0: float = 0.3e-9,
                      detachment: str = "displacement", delta_max: float) -> SummitLaw:
    """Law by name ('jkr', 'dmt', 'maugis_dugdale'), built afresh (`make_summit_law` shares them)."""
    if detachment != "displacement":
        raise ValueError(f"detachment = {detachment!r}: the branch laws release under displacement control only")
    if name == "jkr":
        return jkr_law(beta, w, e_star, delta_max=delta_max)
    if name == "dmt":
        return dmt_law(beta, w, e_star, delta_max=delta_max)
    if name == "maugis_dugdale":
        return maugis_dugdale_law(beta, w, e_star, z0, delta_max=delta_max)
    raise ValueError(f"summit law {name!r}: 'jkr', 'dmt' or 'maugis_dugdale'")


@functools.lru_cache(maxsize=64)
def _shared_summit_law(name: str, beta: float, w: float, e_star: float, z0: float, detachment: str,
                       delta_max: float) -> SummitLaw:
    return _build_summit_law(name, beta, w, e_star, z0=z0, detachment=detachment, delta_max=delta_max)


def make_summit_law(name: str, beta: float, w: float, e_star: float, *, z0: float = 0.3e-9,
                    detachment: str = "displacement", delta_max: float) -> SummitLaw:
    """Law by name ('jkr', 'dmt', 'maugis_dugdale').

    A law is a pure function of these arguments and nothing modifies one after it is built, so each
    distinct set is built once per process and shared (callers must not write into its tables): a
    Maugis-Dugdale law costs a few ms and a scene asks for its summits' law several times (regime map,
    estimates, the contact law, each node of a plastic summit). The cache (64 laws, least recently used
    dropped) is keyed by the values that define the law, however a caller spells them (keywords or
    defaults, NumPy or Python floats; z0 only for Maugis-Dugdale, the one law it enters);
    `make_summit_law.__wrapped__` builds afresh. The tables stay writeable arrays so that compiled kernels
    receive the array types they were compiled for.

    Only displacement-controlled release exists here (summits under a roller are displacement
    driven); detachment = 'load' is refused.
    """
    return _shared_summit_law(str(name), float(beta), float(w), float(e_star),
                              float(z0) if name == "maugis_dugdale" else 0.0, str(detachment), float(delta_max))


make_summit_law.__wrapped__ = _build_summit_law
make_summit_law.cache_info = _shared_summit_law.cache_info
make_summit_law.cache_clear = _shared_summit_law.cache_clear
