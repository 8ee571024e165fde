"""Recipe variants for the adhesion tests: a shipped recipe's settings or recipe with keys overridden at one
fidelity, and a quiet run of one into a cache."""
from __future__ import annotations

import io
import json
from contextlib import redirect_stdout

from md.recipe import load_recipe, parse_recipe
from md.workflows import run_recipe


def settings_with(name, fidelity="smoke", **override):
    """The resolved settings of shipped recipe `name` at `fidelity`, as a dict, with `override` applied."""
    s = dict(load_recipe(name).settings(fidelity))
    s.update(override)
    return s


def recipe_with(name, fidelity="smoke", new_name=None, **override):
    """Shipped recipe `name` with `override` set in its `fidelity` table (renamed `new_name` if given)."""
    t = json.loads(json.dumps(dict(load_recipe(name).raw), default=dict))
    t["fidelity"][fidelity].update(override)
    return parse_recipe(t, name=new_name or name)


def run_quiet(recipe, cache, fidelity="smoke"):
    """`run_recipe` into `cache` with its progress lines swallowed."""
    with redirect_stdout(io.StringIO()):
        return run_recipe(recipe, fidelity, cache=cache, out=None, progress=False)
