"""Shipped data of nanoimpact (scenes, parameter sets, MD recipes, force fields, calibration recipes,
committed MD results). Installed as the package data `nanoimpact.inputs`; found through
`nanoimpact.data`, never by a path relative to the source tree."""
