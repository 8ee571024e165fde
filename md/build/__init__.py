"""Structure builders for the MD workflows: silica slabs and asperities, OTS monolayers, water.

Every builder returns an :class:`ase.Atoms` (view it with ``ase.visualize.view``, write it with ``ase.io.write``)
in LAMMPS ``real`` units (angstrom, e, g/mol): force-field type names (``ff_types``), molecule ids (``mol-id``),
charges and masses as arrays; bonds, angles and dihedrals typed from the force field
(:func:`md.system.topology.with_bonded_terms`), the named groups and a record of what was built (counts, silanol
density and SAM coverage achieved, the random seed, sources) in ``info`` (:func:`md.system.atoms.to_atoms`).
``builder.system(...)`` returns the same build as a :class:`md.system.topology.System`, what the workflows and
the data-file writer work on; builders take either as input. All random choices take a ``seed``; every builder
builds a small valid system with no arguments.

One module per kind of structure: :mod:`~md.build.silica` (slabs, asperities), :mod:`~md.build.sam` (OTS),
:mod:`~md.build.water` (films, cylinders, caps), :mod:`~md.build.dome` (OTS chains on an asperity's dome),
:mod:`~md.build.place` (stacking, flipping);
:mod:`~md.build.common` holds the force fields they type with.
"""
from md.build.common import sam_forcefield, silica_forcefield, water_forcefield
from md.build.dome import graft_dome
from md.build.place import flip_upside_down, place_on
from md.build.sam import ots_sam
from md.build.silica import (
                             CRISTOBALITE_A,
                             DEFAULT_FACE,
                             QUARTZ,
                             SILICA_FACE,
                             quartz_basis,
                             silica_asperity,
                             silica_slab,
)
from md.build.water import cap_radius, water_cap, water_cylinder, water_slab

__all__ = ["silica_slab", "silica_asperity", "ots_sam", "graft_dome", "water_slab", "water_cylinder", "water_cap",
           "place_on", "flip_upside_down", "silica_forcefield", "sam_forcefield", "water_forcefield", "cap_radius",
           "CRISTOBALITE_A", "QUARTZ", "DEFAULT_FACE", "SILICA_FACE", "quartz_basis"]
