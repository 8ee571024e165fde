"""Dimensionless numbers that say which regime a scene is in, and the plasticity checks.

Sources: Tabor, J. Colloid Interface Sci. 58 (1977) 2 (mu = (beta dgamma^2 / (E*^2 z0^3))^(1/3));
Fuller & Tabor, Proc. R. Soc. A 345 (1975) 327 (adhesion parameter: sigma/delta_c, equivalently
theta = E* sigma^(3/2) / (beta^(1/2) dgamma)); Greenwood & Williamson, Proc. R. Soc. A 295 (1966)
300 (plasticity index psi = (E*/H) sqrt(sigma/beta)); Johnson, Contact Mechanics (1985) §4.2 and
§6.2 (line contact: first yield at p_max = 1.67 Y (Tresca) or 1.79 Y (von Mises), nu = 0.3).
"""
from __future__ import annotations

import math

#: Interaction range z0 (m) used for the Tabor parameter until scenes carry their own:
#: the equilibrium separation of the Lennard-Jones surface interaction, ~0.3 nm (Israelachvili,
#: Intermolecular and Surface Forces, 3rd ed. (2011) §13.6 uses D0 = 0.165 nm for the contact
#: cutoff; Tabor 1977 and Maugis 1992 use z0 ~ 0.3-0.4 nm).
Z0_DEFAULT = 0.3e-9

#: First yield of a line (roller) contact as a multiple of the tensile yield strength Y.
LINE_YIELD_TRESCA = 1.67
LINE_YIELD_VON_MISES = 1.79


def tabor_parameter(radius: float, work_of_adhesion: float, e_star: float, z0: float = Z0_DEFAULT) -> float:
    """Tabor's mu = (beta dgamma^2 / (E*^2 z0^3))^(1/3): > ~5 JKR, < ~0.1 DMT (dimensionless)."""
    return (radius * work_of_adhesion**2 / (e_star**2 * z0**3)) ** (1.0 / 3.0)


def fuller_tabor_theta(sigma: float, radius: float, work_of_adhesion: float, e_star: float) -> float:
    """Fuller-Tabor adhesion parameter theta = E* sigma^(3/2) / (beta^(1/2) dgamma) (dimensionless).

    Large theta: adhesion is negligible; theta of a few or less: strong adhesion (FT 1975 Fig. 6).
    """
    if work_of_adhesion == 0.0:
        return math.inf
    return e_star * sigma**1.5 / (math.sqrt(radius) * work_of_adhesion)


def plasticity_index(e_star: float, hardness: float, sigma: float, radius: float) -> float:
    """GW plasticity index psi = (E*/H) sqrt(sigma/beta): < 0.6 elastic summits, > 1 most yield."""
    return e_star / hardness * math.sqrt(sigma / radius)
