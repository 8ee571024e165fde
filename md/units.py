"""The one place where LAMMPS ``units real`` quantities become SI (and back).

Everything in the molecular layer works in LAMMPS ``real`` units (angstrom, femtosecond, kcal/mol, atm,
g/cm^3, e, g/mol) up to the edge, and every number that leaves the layer (``result.json``, curves, the
calibration hand-off) is SI. Every conversion between the two goes through this module -- no other file
multiplies by 4184 or 101325 (the model: ``ase/calculators/lammps/unitconvert.py``).

Constants (from :mod:`scipy.constants`; exact since the 2019 SI redefinition, CODATA 2018):

* Avogadro constant N_A = 6.02214076e23 mol^-1 (exact)
* Boltzmann constant k_B = 1.380649e-23 J/K (exact)
* elementary charge e = 1.602176634e-19 C (exact)
* thermochemical calorie: 1 kcal = 4184 J (exact, the calorie LAMMPS ``real`` uses)
* standard atmosphere: 1 atm = 101325 Pa (exact)

LAMMPS ``real`` energies are per mole of the things they describe: a potential energy of 1 kcal/mol of the
*whole system* is 4184 / N_A J = 6.9477e-21 J of that one system. Forces are kcal/(mol A), pressures atm.

Conversions (``x`` may be a float or a numpy array):

=====================  ====================================  ==============================
LAMMPS real             SI                                    function
=====================  ====================================  ==============================
kcal/mol                J (per system)                        :func:`kcal_per_mol_to_J`
kcal/(mol A)            N                                     :func:`kcal_per_mol_A_to_N`
kcal/(mol A^2)          J/m^2 (energy per area)               :func:`kcal_per_mol_A2_to_J_per_m2`
kcal/(mol A^3)          Pa (force per area: traction)         :func:`kcal_per_mol_A3_to_Pa`
(g/mol) A/fs^2          kcal/(mol A) (mass x acceleration)    :func:`g_per_mol_A_per_fs2_to_kcal_per_mol_A`
A                       m                                     :func:`angstrom_to_m`
fs                      s                                     :func:`fs_to_s`
atm                     Pa                                    :func:`atm_to_Pa`
atm A                   N/m (pressure x length: tension)      :func:`atm_A_to_N_per_m`
g/cm^3                  kg/m^3                                :func:`g_per_cm3_to_kg_per_m3`
A/fs                    m/s                                   :func:`angstrom_per_fs_to_m_per_s`
g/mol                   kg (per particle)                     :func:`g_per_mol_to_kg`
=====================  ====================================  ==============================

and the inverses ``*_from_*`` where the workflows need them (speeds given in m/s in recipes, for example).
:func:`convert` does any of the above by name, for tables.
"""
from __future__ import annotations

import math

import scipy.constants as _C

__all__ = ["AVOGADRO", "BOLTZMANN", "ELEMENTARY_CHARGE", "KCAL", "ATM", "ANGSTROM", "FEMTOSECOND",
           "SPCE_WATER_MOLAR_MASS", "WATER_MOLAR_MASS", "WATER_DENSITY", "R_KCAL_PER_MOL_K",
           "KJ_PER_KCAL",
           "KCAL_PER_MOL", "kcal_per_mol_to_J", "J_to_kcal_per_mol", "kcal_per_mol_A_to_N", "N_to_kcal_per_mol_A",
           "kcal_per_mol_A2_to_J_per_m2", "kcal_per_mol_A3_to_Pa", "g_per_mol_A_per_fs2_to_kcal_per_mol_A",
           "angstrom_to_m", "m_to_angstrom", "fs_to_s", "s_to_fs", "atm_to_Pa",
           "atm_A_to_N_per_m", "g_per_cm3_to_kg_per_m3", "kg_per_m3_to_g_per_cm3", "angstrom_per_fs_to_m_per_s",
           "m_per_s_to_angstrom_per_fs", "g_per_mol_to_kg", "amu_per_A3_to_kg_per_m3", "kT_kcal_per_mol",
           "ns_per_day", "convert", "CONVERSIONS"]

AVOGADRO = _C.Avogadro              #: 1/mol, exact (SI 2019): 6.02214076e23
BOLTZMANN = _C.k                    #: J/K, exact (SI 2019): 1.380649e-23
ELEMENTARY_CHARGE = _C.e            #: C, exact (SI 2019): 1.602176634e-19
KCAL = _C.kilo * _C.calorie         #: J, thermochemical kilocalorie (exact; LAMMPS real): 4184.0
ATM = _C.atm                        #: Pa, standard atmosphere (exact): 101325.0
ANGSTROM = _C.angstrom              #: m
FEMTOSECOND = _C.femto              #: s
KCAL_PER_MOL = KCAL / AVOGADRO      #: J per system for 1 kcal/mol (6.9477e-21 J)
GAS_CONSTANT_KCAL = BOLTZMANN * AVOGADRO / KCAL   #: kcal/(mol K), 1.98720e-3
#: kcal/(mol K): R as CODATA 2018 prints it, 8.314462618 J/(mol K) (not k_B N_A = 8.31446261815...), over the
#: thermochemical kcal; the force-field files' epsilon/k_B values (K) are converted with it, so it stays as is
R_KCAL_PER_MOL_K = 8.314462618 / KCAL
KJ_PER_KCAL = _C.calorie                 #: kJ per kcal (thermochemical): 4.184

# water (the two values are kept apart: results computed with each must not move)
#: g/mol, SPC/E water from its force-field masses (O 15.9994 + 2 H 1.008 = 18.0154): the surface-tension film
SPCE_WATER_MOLAR_MASS = 15.9994 + 2 * 1.008
#: g/mol, the molar mass the contact-angle density maps count each water oxygen with (18.015)
WATER_MOLAR_MASS = 18.015
#: g/cm^3, liquid water at 298 K: the density the water builders fill to
WATER_DENSITY = 0.997


def kcal_per_mol_to_J(x):
    """Energy of one system: kcal/mol -> J."""
    return x * KCAL_PER_MOL


def J_to_kcal_per_mol(x):
    return x / KCAL_PER_MOL


def kcal_per_mol_A_to_N(x):
    """Force: kcal/(mol A) -> N (1 kcal/(mol A) = 69.477 pN)."""
    return x * (KCAL_PER_MOL / ANGSTROM)


def N_to_kcal_per_mol_A(x):
    return x / (KCAL_PER_MOL / ANGSTROM)


def kcal_per_mol_A2_to_J_per_m2(x):
    """Energy per area: kcal/(mol A^2) -> J/m^2 (1 kcal/(mol A^2) = 0.69477 J/m^2)."""
    return x * (KCAL_PER_MOL / ANGSTROM ** 2)


def kcal_per_mol_A3_to_Pa(x):
    """Force per area (a traction, e.g. a mean force between slabs divided by their area): kcal/(mol A^3) -> Pa
    (1 kcal/(mol A^3) = 6.9477e9 Pa)."""
    return x * KCAL_PER_MOL / ANGSTROM ** 3


def g_per_mol_A_per_fs2_to_kcal_per_mol_A(x):
    """Mass x acceleration in LAMMPS real units ((g/mol) A/fs^2, e.g. a momentum change per time) -> the real
    force unit kcal/(mol A): 1 (g/mol) A/fs^2 = 1e7/4184 = 2390.06 kcal/(mol A) (LAMMPS: 1/ftm2v)."""
    return x * (1e-3 * ANGSTROM / FEMTOSECOND ** 2) / (KCAL / ANGSTROM)


def angstrom_to_m(x):
    return x * ANGSTROM


def m_to_angstrom(x):
    return x / ANGSTROM


def fs_to_s(x):
    return x * FEMTOSECOND


def s_to_fs(x):
    return x / FEMTOSECOND


def atm_to_Pa(x):
    return x * ATM


def atm_A_to_N_per_m(x):
    """Pressure times length (e.g. Lz/2 (P_N - P_T)): atm A -> N/m (1 atm A = 1.01325e-5 N/m)."""
    return x * (ATM * ANGSTROM)


def g_per_cm3_to_kg_per_m3(x):
    return x * 1000.0


def kg_per_m3_to_g_per_cm3(x):
    return x / 1000.0


def angstrom_per_fs_to_m_per_s(x):
    """Speed: A/fs -> m/s (1 A/fs = 1e5 m/s)."""
    return x * (ANGSTROM / FEMTOSECOND)


def m_per_s_to_angstrom_per_fs(x):
    return x / (ANGSTROM / FEMTOSECOND)


def g_per_mol_to_kg(x):
    """Mass of one particle: g/mol -> kg."""
    return x * 1e-3 / AVOGADRO


def amu_per_A3_to_kg_per_m3(x):
    """Mass density from (g/mol summed over particles) per A^3 -> kg/m^3."""
    return x * 1e-3 / AVOGADRO / ANGSTROM ** 3


def kT_kcal_per_mol(temperature_K: float) -> float:
    """k_B T in kcal/mol (0.596 kcal/mol at 300 K)."""
    return GAS_CONSTANT_KCAL * temperature_K


def ns_per_day(steps: int, timestep_fs: float, wall_s: float) -> float:
    """Simulated nanoseconds per wall-clock day."""
    if wall_s <= 0:
        return math.nan
    return steps * timestep_fs * 1e-6 / wall_s * 86400.0


#: name -> (LAMMPS real unit, SI unit, factor SI per real unit)
CONVERSIONS: dict[str, tuple[str, str, float]] = {
    "energy": ("kcal/mol", "J", KCAL_PER_MOL),
    "force": ("kcal/mol/A", "N", KCAL_PER_MOL / ANGSTROM),
    "energy_per_area": ("kcal/mol/A^2", "J/m^2", KCAL_PER_MOL / ANGSTROM ** 2),
    "stress": ("kcal/mol/A^3", "Pa", KCAL_PER_MOL / ANGSTROM ** 3),
    "length": ("A", "m", ANGSTROM),
    "time": ("fs", "s", FEMTOSECOND),
    "pressure": ("atm", "Pa", ATM),
    "tension": ("atm*A", "N/m", ATM * ANGSTROM),
    "density": ("g/cm^3", "kg/m^3", 1000.0),
    "velocity": ("A/fs", "m/s", ANGSTROM / FEMTOSECOND),
}


def convert(value, quantity: str, direction: str = "to_si"):
    """Convert ``value`` of ``quantity`` (a key of :data:`CONVERSIONS`) ``to_si`` or ``from_si``."""
    try:
        factor = CONVERSIONS[quantity][2]
    except KeyError:
        raise KeyError(f"unknown quantity {quantity!r}; known: {sorted(CONVERSIONS)}") from None
    if direction == "to_si":
        return value * factor
    if direction == "from_si":
        return value / factor
    raise ValueError(f"direction must be 'to_si' or 'from_si', got {direction!r}")
