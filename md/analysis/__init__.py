"""Analysis of the molecular runs: errors, works of adhesion, contact angles, surface tension, pull-off.

Inputs are what LAMMPS ``units real`` writes (kcal/mol, angstrom, atm, g/mol); every function returns SI
(J/m^2, N/m, N, m, kg/m^3) unless its name or key says otherwise (``angle_deg``, ``*_A``, g/cm^3 density
maps).  Every conversion factor comes from :mod:`md.units`.

One analysis per module: :mod:`~md.analysis.stats`, :mod:`~md.analysis.adhesion`, :mod:`~md.analysis.contact_angle`,
:mod:`~md.analysis.surface_tension`, :mod:`~md.analysis.pulloff`,
:mod:`~md.analysis.free_energy` (W_SL by thermodynamic integration), :mod:`~md.analysis.layer_modulus` (a SAM's
confined modulus from a flat-slab compression branch); the unit factors in :mod:`~md.analysis.common`.

Sources (details and measured accuracies: ``docs/md-analysis.md``):

* block averaging -- Flyvbjerg & Petersen, J. Chem. Phys. 91 (1989) 461;
* cylindrical droplets -- de Ruijter, Blake & De Coninck, Langmuir 15 (1999) 2209 (a droplet periodic
  along one axis has a straight contact line, so its angle carries no line-tension correction);
  Weijs, Marchand, Andreotti, Lohse & Snoeijer, Phys. Fluids 23 (2011) 022001 (circular fit away from
  the wall-layered region);
* circle fits -- Kasa, IEEE Trans. Instrum. Meas. 25 (1976) 8 (algebraic), then geometric least squares;
* surface tension -- Kirkwood & Buff, J. Chem. Phys. 17 (1949) 338; LJ tail: Blokhuis, Bedeaux, Holcomb
  & Zollweg, Mol. Phys. 85 (1995) 665; SPC/E reference: Vega & de Miguel, J. Chem. Phys. 126 (2007)
  154707 (63.6 mN/m at 300 K);
* traction law -- Maugis, J. Colloid Interface Sci. 150 (1992) 243 (LJ 9-3 law, sigma0 = 1.026 w/z0,
  Dugdale range h0 = w/sigma0); Derjaguin, Kolloid Z. 69 (1934) 155 (sphere-flat force = 2 pi R x
  energy per area);
* rate dependence -- Bell, Science 200 (1978) 618; Evans & Ritchie, Biophys. J. 72 (1997) 1541.

:class:`ContactAngle` needs MDAnalysis (the ``md`` extra); everything else needs numpy and scipy only.
"""
from md.analysis.adhesion import (
                                  MAUGIS_LJ93,
                                  chain_correlation,
                                  energy_separation_work,
                                  entropic_term,
                                  flat_slab_range,
                                  force_integration_work,
                                  grid_interval_bounds,
                                  hysteresis,
                                  lj_tail_between,
                                  registry_average,
                                  registry_consistency,
                                  traction_peak,
                                  window_length_check,
                                  work_from_energy_curve,
)
from md.analysis.common import ATM_A_TO_N_PER_M, KCALMOL_PER_A2_TO_J_PER_M2, KCALMOL_PER_A_TO_N
from md.analysis.contact_angle import (
                                  ContactAngle,
                                  cap_angle_for_base,
                                  cap_angle_for_height,
                                  cutoff_crossing_work,
                                  dispersion_tail_work,
                                  dividing_plane,
                                  fit_circle,
                                  fit_contact_angle,
                                  shape_check,
                                  tail_antiderivative,
                                  wetting_bound,
                                  work_of_adhesion_sl,
)
from md.analysis.drift import block_drift
from md.analysis.free_energy import (
                                  angle_from_work_of_adhesion_sl,
                                  film_lower_dividing_plane,
                                  gauss_legendre_unit,
                                  tether_correction,
                                  ti_integral,
                                  ti_work_of_adhesion_sl,
)
from md.analysis.layer_modulus import (
                                  confined_layer_modulus,
                                  plane_strain_from_confined,
                                  poisson_spread,
                                  sam_layer_thickness_A,
                                  small_strain_layer_record,
                                  stress_ratio_poisson,
                                  tangent_confined_modulus,
                                  thickness_at_tilt_A,
                                  tilt_of_anneal,
                                  young_from_confined,
)
from md.analysis.pulloff import fit_traction_law, paired_speed_extrapolation, pull_off_analysis, rate_extrapolation
from md.analysis.stats import (
                                  block_analysis,
                                  block_average,
                                  blocking_stderr,
                                  detect_equilibration,
                                  statistical_inefficiency,
                                  student_t_factor,
                                  timeseries_stats,
)
from md.analysis.surface_tension import density_profile, lj_tail_correction, slab_density, surface_tension

__all__ = [
    "KCALMOL_PER_A2_TO_J_PER_M2", "KCALMOL_PER_A_TO_N", "ATM_A_TO_N_PER_M",
    "block_average", "block_analysis", "blocking_stderr", "statistical_inefficiency", "detect_equilibration",
    "timeseries_stats", "student_t_factor",
    "chain_correlation", "window_length_check", "entropic_term", "grid_interval_bounds", "hysteresis",
    "confined_layer_modulus", "sam_layer_thickness_A", "young_from_confined", "tangent_confined_modulus",
    "thickness_at_tilt_A", "stress_ratio_poisson", "plane_strain_from_confined", "poisson_spread", "tilt_of_anneal",
    "small_strain_layer_record",
    "force_integration_work", "registry_average", "registry_consistency", "traction_peak", "flat_slab_range",
    "lj_tail_between",
    "MAUGIS_LJ93",
    "energy_separation_work", "work_from_energy_curve",
    "ContactAngle", "fit_contact_angle", "fit_circle", "dividing_plane", "wetting_bound", "block_drift",
    "work_of_adhesion_sl", "cap_angle_for_base", "cap_angle_for_height", "shape_check", "dispersion_tail_work",
    "tail_antiderivative", "cutoff_crossing_work",
    "surface_tension", "lj_tail_correction", "density_profile", "slab_density",
    "gauss_legendre_unit", "ti_integral", "ti_work_of_adhesion_sl", "angle_from_work_of_adhesion_sl",
    "tether_correction", "film_lower_dividing_plane", "pull_off_analysis", "fit_traction_law", "rate_extrapolation",
    "paired_speed_extrapolation",
]
