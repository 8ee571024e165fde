"""Assembling built systems: :func:`place_on` stacks one on another; :func:`flip_upside_down` turns one over.
Both take Atoms or Systems.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from md.build.common import _plain, atoms_builder
from md.build.silica import silica_slab
from md.build.water import water_cap
from md.system.atoms import as_system
from md.system.topology import System, merge, translate
from md.system.topology import flip_upside_down as _flip_system

# ================================================================================================ assembly

@atoms_builder
def place_on(substrate: System | None = None, adsorbate: System | None = None, gap: float = 3.0, *,
             vacuum: float = 15.0, center: bool = True, tolerance: float = 1e-3) -> System:
    """Put ``adsorbate`` on top of ``substrate``: its lowest atom ``gap`` (A) above the substrate's highest.

    The box is the substrate's in x, y; z extends ``vacuum`` above the highest atom. Axes along which the
    adsorbate is periodic (``info['periodic_axes']``, default 'xy' for slabs, 'y' for a water cylinder) must
    have the substrate's length (to ``tolerance`` A); along the others the adsorbate is centred on the box
    when ``center`` and must fit. Bonded terms are kept (no bonds across the interface). Groups of the same
    name are concatenated; groups 'substrate' and 'adsorbate' tell the two parts apart.

    With no arguments: an R = 11 A water cap on an 8 x 2 cristobalite (111) slab 10 A thick (a small contact-angle
    system); a missing ``adsorbate`` is that cap, sized to the substrate's y length.
    """
    substrate = silica_slab.system(8, 2, thickness=10.0) if substrate is None else as_system(substrate)
    adsorbate = water_cap.system(11.0, float(substrate.cell[1])) if adsorbate is None else as_system(adsorbate)
    axes = str(adsorbate.info.get("periodic_axes", "xy"))
    shift = np.zeros(3)
    for k, ax in enumerate("xy"):
        if ax in axes:
            if abs(adsorbate.cell[k] - substrate.cell[k]) > tolerance:
                raise ValueError(f"adsorbate is periodic along {ax} with L = {adsorbate.cell[k]:.4f} A but the "
                                 f"substrate has {substrate.cell[k]:.4f} A; build it with the substrate's length")
        else:
            ext = np.ptp(adsorbate.positions[:, k])
            if ext > substrate.cell[k] - 6.0:
                raise ValueError(f"adsorbate extends {ext:.1f} A along {ax}: does not fit the substrate's "
                                 f"{substrate.cell[k]:.1f} A box with a gap to its periodic image")
            if center:
                mid = 0.5 * (adsorbate.positions[:, k].max() + adsorbate.positions[:, k].min())
                shift[k] = 0.5 * substrate.cell[k] - mid
    shift[2] = substrate.positions[:, 2].max() + gap - adsorbate.positions[:, 2].min()
    moved = translate(adsorbate, shift)
    top = moved.positions[:, 2].max()
    cell = (substrate.cell[0], substrate.cell[1], top + vacuum)
    info = {"builder": "place_on", "gap_A": gap, "vacuum_A": vacuum, "periodic_axes": "xy",
            "substrate": dict(substrate.info), "adsorbate": dict(adsorbate.info)}
    out = merge([substrate, moved], cell=cell, pbc=substrate.pbc, info=info)
    info.update(n_atoms=out.n_atoms, counts=out.type_counts(), total_charge=out.total_charge())
    groups = dict(out.groups)
    groups["substrate"] = np.arange(substrate.n_atoms)
    groups["adsorbate"] = np.arange(substrate.n_atoms, out.n_atoms)
    out = replace(out, groups=groups, info=_plain(info))
    return out


@atoms_builder
def flip_upside_down(structure) -> System:
    """``structure`` (Atoms or System) rotated 180 degrees about x (a proper rotation: chirality kept), with its
    ``top``/``bottom`` group names swapped (:func:`md.system.topology.flip_upside_down`)."""
    return _flip_system(as_system(structure))
