"""What a built structure becomes before LAMMPS sees it: the topology (:mod:`~md.system.topology`: typed bonds,
angles and dihedrals, groups, molecule ids), the force fields (:mod:`~md.system.forcefield`: parameter files,
mixing, LAMMPS coefficient lines) and the LAMMPS ``atom_style full`` data file (:mod:`~md.system.lammps_data`:
ours, because ASE's writer drops angles and dihedrals)."""
