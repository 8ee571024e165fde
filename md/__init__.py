"""nanoimpact molecular layer: LAMMPS loading, structure builders, MD workflows and analysis (SI at the edges)."""
