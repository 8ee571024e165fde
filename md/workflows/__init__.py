"""The four MD workflows -- work of adhesion, asperity pull-off, contact angle, liquid-vapour surface tension --
and the front door :func:`run_recipe`.

One module per workflow (:mod:`~md.workflows.adhesion`, :mod:`~md.workflows.pulloff`,
:mod:`~md.workflows.contact_angle`, :mod:`~md.workflows.surface_tension`), each declaring the quantities it yields
(``Workflow.yields``); what they share is :mod:`~md.workflows.common`, the names :mod:`~md.workflows.registry`, the
front door :mod:`~md.workflows.facade`.

Each workflow (1) builds its system with :mod:`md.build` and writes it with :func:`md.system.lammps_data.write_data`,
(2) plans LAMMPS legs for :mod:`md.engine` -- FIRE minimisation first (the builds start strained), NVT
equilibration, sampling -- and (3) turns the stored samples into SI quantities with :mod:`md.analysis`, every
conversion through :mod:`md.units`.

Common LAMMPS set-up: ``units real``, ``atom_style full``, ``boundary p p f``, ``lj/cut/coul/long`` with PPPM
and ``kspace_modify slab 3.0`` (the Yeh-Berkowitz correction: the empty space above the system is tripled
for the Ewald sum, so periodic images along z do not interact), reflecting walls at the z faces of the box
(an evaporated molecule is turned back instead of being lost), pair coefficients and ``special_bonds`` from
the force-field files. Atoms held fixed (slab backs, whole substrates) are left out of the integrator, feel
``setforce 0 0 0`` during minimisation, and their internal pairs are excluded from the neighbour list.

adhesion
    Two slabs in contact (upper slab's back rigid, free along z at zero load) and separated by
    ``separation_A`` (> cutoff; both backs fixed). W = (<E_sep> - <E_contact>) / A from the NVT potential
    energies (:func:`md.analysis.energy_separation_work`). That is an *energy*: with ``free_energy = "pmf"`` the
    mean force between the slabs (``compute group/group`` with ``kspace yes``) is also sampled in windows that
    form chains (each from its neighbour's last state), reach into compression and repeat at several lateral
    registries, and is integrated from its zero-force point (thermodynamic integration along the separation):
    the free energy of separation, T dS = dE - dF, and from the same flat-slab curve sigma0 and
    z0 = 1.026 W_F / sigma0. Dispersion beyond the cutoff is added for TraPPE pairs as a static correction on the
    run's own frames (:func:`md.analysis.lj_tail_between`). Every stderr from the statistical inefficiency.
pulloff
    A hemispherical asperity on a holder, flipped onto a flat. The flat's bottom layer is fixed; the
    holder's back is moved rigidly (``velocity set`` + ``setforce 0 0 0``: constant speed) -- approach, hold,
    retract (``retract_repeats`` times per speed, each with fresh velocities). The flat and the asperity have
    separate thermostats, the asperity's in its own frame (no drag on its motion); the residual drag is measured
    from the holder's reaction. The force on the asperity is ``compute group/group`` (asperity body vs flat,
    ``kspace yes``); the separation is the rigid-holder gap (apex to the top of the flat at the minimised start,
    plus the holder's travel). :func:`md.analysis.pull_off_analysis` gives the maximum tensile force, a 9-3 z0
    (validation only: it absorbs the asperity's compliance) and Delta gamma_eff = F/(1.5 pi R) (JKR) and
    F/(2 pi R) (DMT, the limit at MD scale). At production a rate scan branches several retractions from the same
    held contact and extrapolates (:func:`md.analysis.rate_extrapolation`).
contact_angle
    A cylindrical droplet (periodic along y) on (111) silica with isolated Q3 silanols or on an OTS monolayer.
    The substrate is minimised with nothing held (FIRE at 1 fs), then only its deep Si and bridging O are held
    (silanol O-H by SHAKE) and it is equilibrated alone; the water is added as a cylindrical cap near its expected
    angle; water rigid (SHAKE). Water-oxygen configurations -> :class:`md.analysis.ContactAngle` (an in-memory
    MDAnalysis universe): the angle at the water's own dividing plane, W_SL = gamma_lv (1 + cos theta), a drift
    test of the block angles, and "wets" with an upper bound on the angle when the water spreads into a film.
surface_tension
    A free-standing SPC/E film; gamma = Lz/2 (<Pzz> - (<Pxx> + <Pyy>)/2) from the LAMMPS pressure tensor
    (:func:`md.analysis.surface_tension`) with the analytic LJ tail correction for the truncated LJ term
    (:func:`md.analysis.lj_tail_correction`; Coulomb is long-ranged through PPPM); bulk density from a tanh
    fit of the profile (:func:`md.analysis.slab_density`).
"""
from md.workflows.common import ENERGY_NOT_FREE_ENERGY, Workflow
from md.workflows.facade import MDResult, job_for, run_hash, run_recipe
from md.workflows.registry import WORKFLOWS, get_workflow

__all__ = ["get_workflow", "WORKFLOWS", "Workflow", "ENERGY_NOT_FREE_ENERGY", "MDResult", "run_recipe", "run_hash",
           "job_for"]
