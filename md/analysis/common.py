"""What the analyses share: the LAMMPS ``real`` -> SI factors (all from :mod:`md.units`) and the refined minimum of a
sampled curve."""
from __future__ import annotations

import numpy as np

from md import units as _units

# Every LAMMPS real -> SI factor comes from md.units (the one place for them).
#: 1 kcal/mol/A^2 in J/m^2 (kcal 4184 J, N_A 6.02214076e23: 0.694769...)
KCALMOL_PER_A2_TO_J_PER_M2 = float(_units.kcal_per_mol_A2_to_J_per_m2(1.0))
#: 1 kcal/mol/A in N (6.94769...e-11)
KCALMOL_PER_A_TO_N = float(_units.kcal_per_mol_A_to_N(1.0))
#: 1 atm A in N/m (1.01325e-5)
ATM_A_TO_N_PER_M = float(_units.atm_A_to_N_per_m(1.0))


def refined_min(x, y, i):
    """Minimum near sample i, refined on a cubic spline through the 7 nearest samples (O(h^4)).

    Falls back to the sample itself at the ends of the data or when the spline has no minimum between
    the neighbours of i.
    """
    if i <= 0 or i >= len(x) - 1:
        return float(x[i]), float(y[i])
    from scipy.interpolate import CubicSpline
    from scipy.optimize import minimize_scalar

    lo, hi = max(0, i - 3), min(len(x), i + 4)
    xs, ys = np.asarray(x[lo:hi], float), np.asarray(y[lo:hi], float)
    if np.any(np.diff(xs) <= 0):
        return float(x[i]), float(y[i])
    spl = CubicSpline(xs, ys)
    sol = minimize_scalar(lambda t: float(spl(t)), bounds=(float(x[i - 1]), float(x[i + 1])),
                          method="bounded", options={"xatol": 1e-10 * float(x[i + 1] - x[i - 1])})
    if not sol.success or sol.fun > y[i]:
        return float(x[i]), float(y[i])
    return float(sol.x), float(sol.fun)
