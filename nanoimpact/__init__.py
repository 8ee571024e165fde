"""nanoimpact's shared plumbing: the leaf package that `continuum`, `md` and `calibration` all use.

It holds what every layer needs once -- the version, the error classes and their exit codes,
locating shipped and user data, atomic file writes -- and imports none of the three layers
(`tests/test_architecture.py` checks that).
"""
__version__ = "0.1.0"
