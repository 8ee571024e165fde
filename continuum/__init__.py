"""nanoimpact continuum layer: contact laws, closed-form references and the impact driver (SI units)."""
__version__ = "0.1.0"
