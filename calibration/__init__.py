"""nanoimpact calibration layer: MD results -> continuum parameters, pipelines and the command line."""
