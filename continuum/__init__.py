"""nanoimpact continuum layer: contact laws, closed-form references and the impact driver (SI units).

The front door (imported lazily, so `import continuum.reference.hertz` stays light):

    from continuum import run_scene
    result = run_scene("hertz_roller", overrides={"numerics.max_bounces": 3})
"""
from pathlib import Path as _Path

from nanoimpact import __version__
from nanoimpact.compiled_cache import use_source_keyed_cache as _use_source_keyed_cache

# before any module of the package compiles: numba's cache keyed by these sources (nanoimpact.compiled_cache)
_use_source_keyed_cache(_Path(__file__).parent)

_API = ("run_scene", "load_scene", "read_result", "ImpactResult", "ModelDecision", "EnergyAudit", "EnsembleResult")
__all__ = ["__version__", *_API]


def __getattr__(name: str):
    if name in _API:
        from . import api
        return getattr(api, name)
    raise AttributeError(f"module 'continuum' has no attribute {name!r}")
