"""Plane-strain elastic half-space for a roller's line contact: influence coefficients, FFT
convolution, and the two contact solvers that use them (paper eqs 16-17).

Geometry and signs
------------------
A 1-D grid of ``n_points`` cells of width ``dx`` runs across the roller's axis, cell centres
``x_i = x_center + (i - (N - 1)/2) dx``. On it the local gap is (paper eq 16)

    h(x) = x^2/(2R) + h_ref + delta(x),

where ``delta`` is the elastic normal displacement of the two surfaces *apart* (positive under
compressive pressure: the gap opens relative to the rigid geometry) caused by the pressure
``p(x)`` (Pa; positive = compressive). Force per unit roller length is ``W' = int p dx``; the
total force on a roller of length l is ``l W'``. ``e_star`` is Johnson's effective modulus,
1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (the paper's E*, not Hamrock's E' = 2E*).

Kernel (Johnson, *Contact Mechanics*, 1985, eq 2.19b and §2.8 / eq 2.25c)
-------------------------------------------------------------------------
A line load P' (N/m) on a plane-strain half-space displaces the surface by
``-(2 P'/(pi E*)) ln|x| + C`` (both bodies together, frictionless, so the Dundurs coupling of
normal and tangential displacement is left out). Integrating over a cell carrying uniform
pressure gives the influence coefficient (the same form as Hamrock & Dowson's line-contact
coefficients; exact for piecewise-constant pressure, collocated at cell centres):

    D_k = -(2/(pi E*)) [F(k dx + dx/2) - F(k dx - dx/2)],   F(u) = u ln(|u|/x_ref) - u,

and ``delta_i = sum_j D_(i-j) p_j``. The matrix is symmetric Toeplitz, so ``delta`` is a linear
(non-periodic) convolution, done with a zero-padded real FFT of length >= 2N (the kernel's
transform is computed once in the constructor): O(N log N), no periodic images.

The reference point ``x_ref``
-----------------------------
The 2-D displacement is defined only up to a constant: a line load has no finite displacement
"at infinity" (ln|x| diverges). We fix the constant by measuring displacements relative to the
surface points at distance ``x_ref`` from the load: a line load produces zero displacement at
|x - s| = x_ref, and a distributed load of resultant W' produces
``delta(x) -> -(2W'/(pi E*)) ln(|x|/x_ref) + O((b/x)^2)`` far from the contact. Changing
x_ref to x_ref' adds the uniform constant ``(2W'/(pi E*)) ln(x_ref'/x_ref)`` to ``delta``.

*Why the constant folds into h_ref.* The gap is ``x^2/2R + (h_ref + C) + delta_shape(x)``: the
pressure distribution, the footprint and the gap field depend only on the sum ``h_ref + C``.
Any choice of x_ref is a relabelling of h_ref. For the dynamics (paper eqs 13-15) this
relabelling is not free, because C is proportional to the load: measuring ``h_ref`` from a
reference at distance x_ref is equivalent to putting a linear spring of compliance
``(2/(pi E* l)) ln(x_ref'/x_ref)`` in series with the contact. The "approach" of a 2-D contact
is therefore undefined until the reference is stated; physically it is set by the finite size
of the bodies. For Hertz pressure, the displacement at the centre is exactly

    delta(0) = (W'/(pi E*)) (2 ln(2 x_ref/b) + 1),

(using int_{-1}^{1} sqrt(1 - t^2) ln|t| dt = -(pi/2)(ln 2 + 1/2)), so the rigid approach
``-h_ref`` of a Hertz roller equals Johnson's finite-length result (Contact Mechanics eq 5.39)
``W = pi l E* delta / (2 ln(2l/b) + 1)`` -- the paper's K of eq 1 -- *if and only if*
``x_ref = l``, the roller length. Pass ``x_ref = l`` for impact dynamics so that the numerical
half-space and the closed-form roller law share one datum. The default (``x_ref = None``) is the
grid span ``N dx``: harmless for static, reference-free quantities (pressure, footprint, gap
differences), but it moves with the grid, so never use the default in a dynamic run whose grid
follows the footprint.

Solvers
-------
``solve_hard_contact``: frictionless, non-adhesive complementarity (p >= 0, h >= 0, p h = 0)
at a prescribed load per length, by the constrained conjugate-gradient method of Polonsky &
Keer, Wear 231 (1999) 206-219, in 1-D with the FFT operator. It returns the rigid approach
(``h_ref``) as the Lagrange multiplier of the load constraint.

``solve_coupled``: prescribed rigid gap (``h_ref`` given) and a pressure law p(h) that may be
tensile. Newton-Krylov (matrix-free GMRES on J = I - diag(dp/dh) D, Jacobi-preconditioned,
with a backtracking line search and a residual-proportional forcing term); on failure
pseudo-transient continuation (which can only settle on stable states, and so finds the state
the surfaces snap to when a branch ends), then a damped fixed-point iteration. See its
docstring for measured iteration counts.

``choose_grid``: a grid whose span follows the footprint (a few Hertz half-widths, or the
region where the rigid gap is below the law's range).

Positive definiteness: the kernel ln(x_ref/|x - s|) is positive definite on a segment of length
L only if x_ref > L/4 (the segment's logarithmic capacity; the discrete matrix's smallest
eigenvalue changes sign between x_ref = 0.24 L and 0.25 L), so the constructor refuses
x_ref <= N dx / 4. Then the elastic energy is convex, the Polonsky-Keer CG is well posed, and
J's eigenvalues are positive exactly at stable states.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy import fft as sfft
from scipy.linalg import toeplitz
from scipy.sparse.linalg import LinearOperator, gmres

from ..reference.hertz import line_half_width

PressureLaw = Callable[[np.ndarray], "tuple[np.ndarray, np.ndarray]"]

__all__ = [
    "LineHalfSpace", "Grid", "choose_grid", "solve_hard_contact", "solve_coupled",
    "HardContactSolution", "CoupledSolution", "strip_displacement",
]


# --------------------------------------------------------------------------- closed forms
def strip_displacement(x, half_width: float, pressure: float, e_star: float, x_ref: float, center: float = 0.0):
    """Displacement (m) of uniform pressure on the strip |x - center| <= a (Johnson eq 2.25c).

    ``-(p/(pi E*)) [(x+a) ln((x+a)/x_ref)^2 - (x-a) ln((x-a)/x_ref)^2] + const``; the constant is
    fixed by the same reference as :class:`LineHalfSpace` (zero displacement of a line load at
    distance x_ref), which makes it ``-(2p/(pi E*)) (-2a)``.
    """
    u = np.asarray(x, dtype=float) - center
    return -(2.0 * pressure / (math.pi * e_star)) * (_F(u + half_width, x_ref) - _F(u - half_width, x_ref))


def _F(u, x_ref):
    """Antiderivative of ln(|u|/x_ref): u ln(|u|/x_ref) - u, with F(0) = 0."""
    u = np.asarray(u, dtype=float)
    au = np.abs(u)
    with np.errstate(divide="ignore", invalid="ignore"):
        val = u * np.log(np.where(au > 0, au, 1.0) / x_ref) - u
    return np.where(au > 0, val, 0.0)


# --------------------------------------------------------------------------- the operator
class LineHalfSpace:
    """Plane-strain elastic half-space on a uniform 1-D grid (see module docstring for the kernel).

    Parameters
    ----------
    x_spacing : float
        Cell width dx (m).
    n_points : int
        Number of cells N.
    e_star : float
        Johnson's effective modulus E* (Pa).
    x_ref : float, optional
        Reference distance (m): a line load gives zero displacement at this distance from it.
        Use the roller length l in dynamics (then the centre approach of a Hertz roller is
        Johnson's eq 5.39, the paper's K). Default: the grid span N dx (static use only).
    x_center : float, optional
        Position of the grid's centre (m); default 0.

    Attributes
    ----------
    x : ndarray
        Cell centres (m).
    coefficients : ndarray
        D_k, k = 0..N-1 (m/Pa): displacement at distance k dx from a cell with unit pressure.
    """

    def __init__(self, x_spacing: float, n_points: int, e_star: float, *, x_ref: float | None = None,
                 x_center: float = 0.0):
        if not (x_spacing > 0 and math.isfinite(x_spacing)):
            raise ValueError(f"x_spacing = {x_spacing!r}: must be a positive length (m)")
        if int(n_points) != n_points or n_points < 2:
            raise ValueError(f"n_points = {n_points!r}: must be an integer >= 2")
        if not (e_star > 0):
            raise ValueError(f"e_star = {e_star!r}: must be a positive modulus (Pa)")
        self.dx = float(x_spacing)
        self.n = int(n_points)
        self.e_star = float(e_star)
        self.x_ref_is_default = x_ref is None
        self.x_ref = float(self.n * self.dx if x_ref is None else x_ref)
        if not self.x_ref > 0.25 * self.n * self.dx:
            raise ValueError(
                f"x_ref = {self.x_ref!r} m: must exceed a quarter of the grid span ({0.25 * self.n * self.dx!r} m). "
                "The kernel ln(x_ref/|x - s|) is positive definite on a segment only when x_ref exceeds the "
                "segment's logarithmic capacity (span/4); below it the elastic energy is not convex. "
                "Use the roller length for dynamics")
        self.x_center = float(x_center)
        self.x = self.x_center + (np.arange(self.n) - 0.5 * (self.n - 1)) * self.dx

        k = np.arange(self.n) * self.dx
        h = 0.5 * self.dx
        self.coefficients = -(2.0 / (math.pi * self.e_star)) * (_F(k + h, self.x_ref) - _F(k - h, self.x_ref))
        self.nfft = sfft.next_fast_len(2 * self.n, real=True)
        kern = np.zeros(self.nfft)
        kern[: self.n] = self.coefficients
        kern[self.nfft - self.n + 1:] = self.coefficients[1:][::-1]
        self._kernel_hat = sfft.rfft(kern)
        self._row_abs_sums = None

    @property
    def self_compliance(self) -> float:
        """D_0 (m/Pa): displacement of a cell under its own unit pressure."""
        return float(self.coefficients[0])

    def displacement(self, p) -> np.ndarray:
        """delta = D p (m) for pressures ``p`` (Pa) of shape (..., N); O(N log N) per row."""
        p = np.asarray(p, dtype=float)
        if p.shape[-1] != self.n:
            raise ValueError(f"pressure has {p.shape[-1]} points along its last axis; the grid has {self.n}")
        out = sfft.irfft(sfft.rfft(p, n=self.nfft, axis=-1) * self._kernel_hat, n=self.nfft, axis=-1)
        return out[..., : self.n]

    __call__ = displacement

    def row_abs_sums(self) -> np.ndarray:
        """sum_j |D_ij| for each row i (m/Pa): bounds the operator's norm (used to damp fixed points)."""
        if self._row_abs_sums is None:
            kern = np.zeros(self.nfft)
            a = np.abs(self.coefficients)
            kern[: self.n] = a
            kern[self.nfft - self.n + 1:] = a[1:][::-1]
            self._row_abs_sums = sfft.irfft(sfft.rfft(np.ones(self.n), n=self.nfft) * sfft.rfft(kern),
                                            n=self.nfft)[: self.n]
        return self._row_abs_sums

    def dense_matrix(self) -> np.ndarray:
        """The N x N influence matrix (symmetric Toeplitz); for tests and small problems."""
        return toeplitz(self.coefficients)

    def load_per_length(self, p) -> np.ndarray:
        """Force per unit length int p dx (N/m) for pressures of shape (..., N)."""
        return np.sum(np.asarray(p, dtype=float), axis=-1) * self.dx

    def describe(self) -> dict:
        """JSON-ready description of the discretisation and reference."""
        return {"name": "line_half_space", "source": "Johnson (1985) eqs 2.19b, 2.25c; plane strain",
                "x_spacing": self.dx, "n_points": self.n, "e_star": self.e_star, "x_ref": self.x_ref,
                "x_ref_source": "grid span (default)" if self.x_ref_is_default else "given",
                "x_center": self.x_center, "fft_length": self.nfft}


# --------------------------------------------------------------------------- grid choice
@dataclass(frozen=True)
class Grid:
    """A uniform grid of ``n_points`` cells of width ``x_spacing`` covering |x - x_center| <= half_span."""

    x_spacing: float
    n_points: int
    half_span: float
    x_center: float = 0.0
    why: str = ""

    @property
    def x(self) -> np.ndarray:
        return self.x_center + (np.arange(self.n_points) - 0.5 * (self.n_points - 1)) * self.x_spacing

    def half_space(self, e_star: float, x_ref: float | None = None) -> LineHalfSpace:
        return LineHalfSpace(self.x_spacing, self.n_points, e_star, x_ref=x_ref, x_center=self.x_center)


def choose_grid(radius: float, load_per_length: float, e_star: float, *, n_points: int = 256,
                span: float = 2.0, h_ref: float | None = None, gap_height: float | None = None,
                gap_margin: float = 1.25, min_half_span: float = 0.0) -> Grid:
    """A grid that follows the footprint.

    The half-span is the largest of
      * ``span`` x the Hertz half-width b(W') (if ``load_per_length`` > 0);
      * ``gap_margin`` x the rigid footprint where x^2/2R + h_ref <= ``gap_height`` (if both
        ``h_ref`` and ``gap_height`` are given: use the range of the pressure law, e.g. a few
        summit sigma for a rough surface, so every cell where the law is non-zero is on the grid);
      * ``min_half_span``.
    Cells are 2 half_span / n_points wide and centred on x = 0.
    """
    candidates = {}
    if load_per_length > 0:
        # Hertz half-width per unit length: the roller of length 1 m under load_per_length (Johnson §4.2)
        candidates["hertz"] = span * float(line_half_width(load_per_length, radius, 1.0, e_star))
    if h_ref is not None and gap_height is not None and gap_height > h_ref:
        candidates["gap"] = gap_margin * math.sqrt(2.0 * radius * (gap_height - h_ref))
    if min_half_span > 0:
        candidates["minimum"] = min_half_span
    if not candidates:
        raise ValueError("choose_grid needs load_per_length > 0, or h_ref < gap_height, or min_half_span > 0")
    why, half = max(candidates.items(), key=lambda kv: kv[1])
    return Grid(2.0 * half / n_points, int(n_points), half, 0.0,
                {"hertz": f"{span} x Hertz half-width", "gap": f"{gap_margin} x rigid footprint below gap_height",
                 "minimum": "min_half_span"}[why])


# --------------------------------------------------------------------------- hard contact
@dataclass
class HardContactSolution:
    """Result of :func:`solve_hard_contact` (SI): pressure, displacement, gap, rigid approach."""

    p: np.ndarray
    delta: np.ndarray
    h: np.ndarray
    h_ref: float
    iterations: int
    residual: float
    converged: bool
    x: np.ndarray = field(repr=False, default=None)

    @property
    def touches_edge(self) -> bool:
        """True if the footprint reaches the first or last cell: the grid is too small."""
        return bool(self.p[0] > 0 or self.p[-1] > 0)

    @property
    def approach(self) -> float:
        """-h_ref (m): rigid approach relative to the half-space's reference (x_ref)."""
        return -self.h_ref


def solve_hard_contact(halfspace: LineHalfSpace, gap0, load_per_length: float, *, tol: float = 1e-12,
                       max_iter: int = 2000, p_init=None) -> HardContactSolution:
    """Frictionless non-adhesive contact at prescribed load per length (Polonsky & Keer 1999).

    Finds p >= 0 and the rigid approach such that h = gap0 + h_ref + D p >= 0, p h = 0 and
    sum(p) dx = ``load_per_length``. ``gap0`` is the undeformed geometry without the rigid
    offset (e.g. x^2/2R). The algorithm is Polonsky & Keer's constrained conjugate gradient
    (Wear 231 (1999) 206-219): CG on the current contact set with the mean gap removed (the mean
    is the Lagrange multiplier of the load, i.e. -h_ref), pressures clipped at zero, penetrating
    free cells re-admitted with a steepest-descent step (CG restarted), and the load restored by
    scaling. It is independent of x_ref except through the returned ``h_ref``.

    Convergence: relative pressure change dx sum|p - p_old| / W' < ``tol``. ``residual`` is the
    final relative change; the complementarity error is ~tol x the gap scale.
    """
    hs = halfspace
    gap0 = np.asarray(gap0, dtype=float)
    if gap0.shape != (hs.n,):
        raise ValueError(f"gap0 has shape {gap0.shape}; the grid has {hs.n} points")
    if not load_per_length > 0:
        raise ValueError(f"load_per_length = {load_per_length!r}: must be > 0 (no contact otherwise)")
    W, dx = float(load_per_length), hs.dx
    if p_init is None:
        p = np.full(hs.n, W / (hs.n * dx))
    else:
        p = np.clip(np.asarray(p_init, dtype=float), 0.0, None).copy()
        if p.shape != (hs.n,) or not p.sum() > 0:
            raise ValueError("p_init must be N pressures with a positive sum (a previous solution)")
        p *= W / (p.sum() * dx)
    t = np.zeros(hs.n)
    g_old, restart_ok = 1.0, False
    eps = np.inf
    it = 0
    for it in range(1, max_iter + 1):
        g = hs.displacement(p) + gap0
        ic = p > 0
        g -= g[ic].mean()
        G = float(np.dot(g[ic], g[ic]))
        beta = G / g_old if restart_ok else 0.0
        t = np.where(ic, g + beta * t, 0.0)
        g_old = G
        r = hs.displacement(t)
        r -= r[ic].mean()
        denom = float(np.dot(r[ic], t[ic]))
        tau = float(np.dot(g[ic], t[ic])) / denom if denom != 0 else 0.0
        p_old = p.copy()
        p = p - tau * t
        p[p < 0] = 0.0
        overlap = (p <= 0) & (g < 0)
        if np.any(overlap):
            restart_ok = False
            p[overlap] -= tau * g[overlap]
        else:
            restart_ok = True
        p *= W / (p.sum() * dx)
        eps = float(np.abs(p - p_old).sum() * dx / W)
        if eps < tol:
            break
    delta = hs.displacement(p)
    ic = p > 0
    h_ref = -float(np.mean(gap0[ic] + delta[ic]))
    h = gap0 + h_ref + delta
    return HardContactSolution(p, delta, h, h_ref, it, eps, eps < tol, hs.x)


# --------------------------------------------------------------------------- coupled solve
@dataclass
class CoupledSolution:
    """Result of :func:`solve_coupled` (SI).

    ``p`` (Pa), ``delta`` (m), ``h`` (m) on the grid; ``iterations``: nonlinear iterations of all
    stages together; ``residual`` = max|p - P(h)| / pressure scale; ``method``: the stage that
    produced the answer ("newton", "ptc" or "fixed_point"); ``matvecs``: FFT convolutions used;
    ``load_per_length`` = sum(p) dx (N/m), the net force per unit length (tensile < 0);
    ``history``: (stage, iteration, residual, step info) tuples.
    """

    p: np.ndarray
    delta: np.ndarray
    h: np.ndarray
    iterations: int
    residual: float
    converged: bool
    method: str
    matvecs: int
    load_per_length: float
    history: list = field(default_factory=list, repr=False)


class _Counter:
    def __init__(self, hs):
        self.hs, self.n = hs, 0

    def __call__(self, p):
        self.n += 1
        return self.hs.displacement(p)


def _scale(p, P, pressure_scale):
    if pressure_scale is not None:
        return pressure_scale
    s = max(float(np.max(np.abs(p))), float(np.max(np.abs(P))))
    return s if s > 0 else 1.0


_METHODS = ("newton", "ptc", "fixed_point")


def solve_coupled(halfspace: LineHalfSpace, gap_rigid, pressure_law: PressureLaw, *, p_init=None,
                  method: str = "newton", fallback: bool = True, tol: float = 1e-10, max_iter: int = 50,
                  max_ptc_iter: int = 300, max_fixed_point_iter: int = 5000,
                  pressure_scale: float | None = None, gmres_restart: int = 60,
                  gmres_maxiter: int = 20) -> CoupledSolution:
    """Self-consistent pressure and deformation for a prescribed rigid gap.

    Solves ``p = P(h)`` with ``h = gap_rigid + D p`` (``gap_rigid`` = x^2/2R + h_ref, h_ref given),
    where ``pressure_law(h)`` returns ``(p, dp/dh)`` arrays; p may be negative (adhesion). The law
    is evaluated at trial gaps, so it must be a pure function of h during the solve (a
    history-dependent law is frozen here and updated by the caller once the step is accepted).

    Stages (``method`` picks the first; with ``fallback`` the later ones follow on failure,
    each restarted from ``p_init``, except the fixed point, which starts from the best iterate)
    ------------------------------------------------------------------------------------------
    ``"newton"``: Newton-Krylov on F(p) = p - P(gap_rigid + D p). The Jacobian
    J = I - diag(dp/dh) D is applied matrix-free (one FFT convolution per product) inside
    ``scipy.sparse.linalg.gmres`` with the Jacobi preconditioner diag(1 - (dp/dh)_i D_0); the
    forcing term is min(0.1, relative residual) (superlinear, quadratic in the limit); steps are
    globalised by Armijo backtracking on ||F||_2 (halving, down to 1/1024).

    ``"ptc"``: pseudo-transient continuation (Kelley & Keyes, SIAM J. Numer. Anal. 35 (1998) 508;
    switched evolution relaxation of Mulder & van Leer 1985): implicit Euler steps of
    dp/dtau = -F(p), (I/dtau + J) dp = -F, with dtau *= ||F_old||/||F_new|| (dtau -> inf is
    Newton). Since J = (A^-1 - diag(dp/dh)) D (A := D, SPD), J's eigenvalues have positive real
    parts exactly where the elastic + interaction energy has a minimum, so this relaxation can
    only settle on a stable state. It is what rescues a cold start at an h_ref where the branch
    the start lies on has ended (adhesive snap-in or snap-off): Newton's line search then
    stalls, and PTC relaxes to the state the surfaces jump to.

    ``"fixed_point"``: Picard iteration p <- p - w F(p) with w = 2/(2 + mu), mu = max_i |dp/dh|_i
    sum_j |D_ij| (bounds the spectral radius of diag(dp/dh) D), halving a safety factor when
    ||F|| grows. It needs O(mu) iterations: fine for weak coupling, hopeless for stiff laws.

    Measured (tests' set-up: N = 256, R = 5 um, E* = 100 GPa, x_ref = 3.3 mm, h_ref = the hard
    contact's approach at W' = 1 N/m, cold start p = 0; coupling mu = max|dp/dh| sum_j |D_ij|;
    table in docs/halfspace.md). Exponential wall p0 exp(-h/lam), lam = 1e-9 ... 1e-15 m
    (mu = 0.2 ... 2e5): Newton 3, 4, 5, 6, 6, 8, 10, 14 iterations; PTC 6, 5, 6, 6, 6, 8, 14, 22;
    fixed point 10, 24, 334, 2686 (lam = 1e-9 ... 3e-12), then no convergence in 5000. With a
    tensile well (depth 0.1-1 p0, range 1e-12 - 1e-11 m): Newton 2-18 iterations wherever the
    cold start lies on a surviving branch, but its line search stalls next to snap-in (5 of 20
    cases), where PTC converged in 17-47; the fixed point converged only in 6 of 20 cases, all
    with the surfaces (nearly) apart. Hence the default order newton -> ptc -> fixed_point. In
    this project's rough-surface regime (GW-like exponential law, sigma = 6 nm, W' ~ 0.02 N/m,
    E* = 85 GPa, x_ref = 3.3 mm: mu ~ 1e-4 - 1e-3, deflections of picometres against gaps of
    nanometres) all three converge: Newton in 2 iterations, the fixed point in 3, PTC in 6 (its
    first pseudo-time step is deliberately short).

    Parameters
    ----------
    halfspace : LineHalfSpace
    gap_rigid : array (N,)
        x^2/2R + h_ref on the grid (m).
    pressure_law : callable
        h (m) -> (p (Pa), dp/dh (Pa/m)).
    p_init : array, optional
        Warm start (e.g. the previous time step's pressure); default zero pressure.
    tol : float
        Stop when max|p - P(h)| <= tol x pressure scale (default scale: max(|p|, |P(h)|)).
    """
    hs = halfspace
    g = np.asarray(gap_rigid, dtype=float)
    if g.shape != (hs.n,):
        raise ValueError(f"gap_rigid has shape {g.shape}; the grid has {hs.n} points")
    if method not in _METHODS:
        raise ValueError(f"method = {method!r}: must be one of {_METHODS}")
    D = _Counter(hs)
    p0 = np.zeros(hs.n) if p_init is None else np.asarray(p_init, dtype=float).copy()
    if p0.shape != (hs.n,):
        raise ValueError(f"p_init has shape {p0.shape}; the grid has {hs.n} points")
    history: list = []

    def evaluate(p):
        delta = D(p)
        h = g + delta
        P, dP = pressure_law(h)
        return delta, h, np.asarray(P, dtype=float), np.asarray(dP, dtype=float)

    stages = _METHODS[_METHODS.index(method):] if fallback else (method,)
    total, best = 0, None
    for stage in stages:
        start = p0 if stage != "fixed_point" or best is None else best[0]
        if stage == "newton":
            out = _newton(hs, D, evaluate, start, tol, max_iter, pressure_scale, gmres_restart,
                          gmres_maxiter, history, ptc=False)
        elif stage == "ptc":
            out = _newton(hs, D, evaluate, start, tol, max_ptc_iter, pressure_scale, gmres_restart,
                          gmres_maxiter, history, ptc=True)
        else:
            out = _fixed_point(hs, evaluate, start, tol, max_fixed_point_iter, pressure_scale, history)
        p, delta, h, P, it, res, ok = out
        total += it
        if best is None or res < best[5]:
            best = (p, delta, h, P, it, res, ok, stage)
        if ok:
            return CoupledSolution(p, delta, h, total, res, True, stage, D.n, float(np.sum(p) * hs.dx), history)
    p, delta, h, P, it, res, ok, stage = best
    return CoupledSolution(p, delta, h, total, res, False, stage, D.n, float(np.sum(p) * hs.dx), history)


def _newton(hs, D, evaluate, p, tol, max_iter, pressure_scale, restart, maxiter, history, ptc):
    """Newton-Krylov with line search (ptc=False) or pseudo-transient continuation (ptc=True)."""
    name = "ptc" if ptc else "newton"
    d0 = hs.self_compliance
    delta, h, P, dP = evaluate(p)
    F = p - P
    norm = float(np.linalg.norm(F))
    res = float(np.max(np.abs(F))) / _scale(p, P, pressure_scale)
    history.append((name, 0, res, None))
    best = (p, delta, h, P, res)
    shift = 1.0  # 1/dtau for PTC
    it = 0
    for it in range(1, max_iter + 1):
        if res <= tol:
            return p, delta, h, P, it - 1, res, True
        k = dP.copy()
        s = shift if ptc else 0.0
        jac = LinearOperator((hs.n, hs.n), matvec=lambda v, k=k, s=s: (1.0 + s) * v - k * D(v), dtype=float)
        diag = 1.0 + s - k * d0
        diag = np.where(diag > 1e-3, diag, 1.0)
        prec = LinearOperator((hs.n, hs.n), matvec=lambda v, diag=diag: v / diag, dtype=float)
        eta = min(0.1, max(res, 1e-3 * tol))
        step, _info = gmres(jac, -F, rtol=eta, atol=0.0, restart=restart, maxiter=maxiter, M=prec)
        if ptc:
            p_try = p + step
            delta_t, h_t, P_t, dP_t = evaluate(p_try)
            F_t = p_try - P_t
            if not np.all(np.isfinite(F_t)):
                shift *= 10.0
                history.append((name, it, res, "non-finite: smaller pseudo-time step"))
                continue
            norm_t = float(np.linalg.norm(F_t))
            shift = shift * norm_t / norm if norm > 0 else 0.0
            shift = min(max(shift, 1e-12), 1e12)
            info = 1.0 / shift
        else:
            f0 = norm * norm
            alpha, accepted = 1.0, False
            while alpha >= 1.0 / 1024:
                p_try = p + alpha * step
                delta_t, h_t, P_t, dP_t = evaluate(p_try)
                F_t = p_try - P_t
                if np.all(np.isfinite(F_t)):
                    norm_t = float(np.linalg.norm(F_t))
                    if norm_t * norm_t <= (1.0 - 1e-4 * alpha) ** 2 * f0:
                        accepted = True
                        break
                alpha *= 0.5
            if not accepted:
                history.append((name, it, res, "line search failed"))
                return (*best[:4], it, best[4], False)
            info = alpha
        p, delta, h, P, dP, F, norm = p_try, delta_t, h_t, P_t, dP_t, F_t, norm_t
        res = float(np.max(np.abs(F))) / _scale(p, P, pressure_scale)
        history.append((name, it, res, info))
        if res < best[4]:
            best = (p, delta, h, P, res)
    if res <= tol:
        return p, delta, h, P, it, res, True
    return (*best[:4], it, best[4], False)


def _fixed_point(hs, evaluate, p, tol, max_iter, pressure_scale, history):
    # Picard step p <- p - w F(p). For a repulsive law the iteration matrix (1 - w) I + w diag(P') D
    # has eigenvalues 1 - w (1 + mu), 0 <= mu <= mu_max <= max_i |P'_i| sum_j |D_ij| (an induced
    # norm bounds the spectral radius), so w = 2 / (2 + mu_bound) is safe and close to optimal.
    # A safety factor s (halved whenever ||F|| exceeds twice its best value) guards the rest.
    rows = hs.row_abs_sums()
    delta, h, P, dP = evaluate(p)
    F = p - P
    norm = best_norm = float(np.linalg.norm(F))
    res = float(np.max(np.abs(F))) / _scale(p, P, pressure_scale)
    best = (p, delta, h, P, res)
    history.append(("fixed_point", 0, res, None))
    safety = 1.0
    it = 0
    for it in range(1, max_iter + 1):
        if res <= tol:
            return p, delta, h, P, it - 1, res, True
        mu = float(np.max(np.abs(dP) * rows))
        w = safety * 2.0 / (2.0 + mu)
        p = p - w * F
        delta, h, P, dP = evaluate(p)
        F = p - P
        norm = float(np.linalg.norm(F)) if np.all(np.isfinite(F)) else np.inf
        if not norm <= 2.0 * best_norm:
            p, delta, h, P = best[:4]
            _, _, _, dP = evaluate(p)
            F = p - P
            safety *= 0.5
            if safety < 1e-6:
                break
            continue
        res = float(np.max(np.abs(F))) / _scale(p, P, pressure_scale)
        if norm < best_norm:
            best_norm, best = norm, (p, delta, h, P, res)
        history.append(("fixed_point", it, res, w))
    p, delta, h, P, res = best
    return p, delta, h, P, it, res, res <= tol
