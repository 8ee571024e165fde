"""One iteration of Brent's root-finding method, compiled, as SciPy's `brentq` takes it (scipy/optimize/Zeros/brentq.c,
after R. P. Brent, *Algorithms for Minimization without Derivatives*, Prentice-Hall 1973, ch. 4): the compiled
contact phase's event roots (`continuum.numerics.contact_kernel`) and the plastic mean field's set edges
(`continuum.rough.plastic_gw_kernel`) drive it with their own function and iteration limit."""
from __future__ import annotations

from numba import njit


@njit(cache=True)
def brent_step(xpre, xcur, xblk, fpre, fcur, fblk, spre, scur, xtol, rtol):
    """One step once f(xcur) = fcur is known: (converged, xpre, xcur, xblk, fpre, fblk, spre, scur). Converged: xcur
    is the root; otherwise xcur is the next point, at which the caller evaluates f before the next step. Start with
    xpre, xcur the bracket's ends, their f values, and xblk = fblk = spre = scur = 0."""
    if fpre != 0.0 and fcur != 0.0 and (fpre < 0.0) != (fcur < 0.0):
        xblk, fblk = xpre, fpre
        spre = scur = xcur - xpre
    if abs(fblk) < abs(fcur):
        xpre, xcur, xblk = xcur, xblk, xcur
        fpre, fcur, fblk = fcur, fblk, fcur
    delta = 0.5 * (xtol + rtol * abs(xcur))
    sbis = 0.5 * (xblk - xcur)
    if fcur == 0.0 or abs(sbis) < delta:
        return True, xpre, xcur, xblk, fpre, fblk, spre, scur
    if abs(spre) > delta and abs(fcur) < abs(fpre):
        if xpre == xblk:
            stry = -fcur * (xcur - xpre) / (fcur - fpre)
        else:
            dpre = (fpre - fcur) / (xpre - xcur)
            dblk = (fblk - fcur) / (xblk - xcur)
            stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
        if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
            spre, scur = scur, stry
        else:
            spre = scur = sbis
    else:
        spre = scur = sbis
    xpre, fpre = xcur, fcur
    if abs(scur) > delta:
        xcur += scur
    else:
        xcur += delta if sbis > 0.0 else -delta
    return False, xpre, xcur, xblk, fpre, fblk, spre, scur
