"""The compiled form of discrete summits with a bridge each (`continuum.laws.wet_summits`) after t_a: its parameters,
tables and history as `continuum.numerics.wet_discrete_kernel` reads them, and the history taken back.

Before t_a the wet law is its dry law and runs the dry kernel, stopped at t_a (`WetRoughRoller.compiled`); at t_a
the driver samples and accepts the state in Python (bridges condense on every summit in contact), then asks the law
again: `wet_form` hands the contact on to the kernel with every book of the Python law (attached flags, bridged
prefix, loops, switch and formation work, the bridges' offset and clock), and `take_back` writes the kernel's
history back, so a contact may end in either form with the same books.
"""
from __future__ import annotations

import math

import numpy as np

from ..numerics import wet_discrete_kernel as wk
from ..numerics.compiled_contact import EMPTY_TABLES, CompiledLaw


def _class_block(law, tables: list, P: np.ndarray, base: int) -> None:
    """Class block at P[base:] for the per-summit law of the discrete roller `law` (tabulated branches, closed-form
    JKR or Hertz); its branch tables appended to `tables` (rows of delta, force, energy)."""
    P[base + wk.C_IN], P[base + wk.C_OUT] = law._delta_in, -law.release_stretch
    P[base + wk.C_REACH], P[base + wk.C_LOOP] = law._reach, law.loop_energy
    P[base + wk.C_HERTZ_K] = law._hertz_k
    if law.slaw is not None:
        P[base + wk.C_MODE] = wk.MODE_BRANCH
        offset = sum(t[0].size for t in tables)
        for branch, lo, hi in ((law.slaw.approach, wk.C_A_LO, wk.C_A_HI), (law.slaw.retreat, wk.C_R_LO, wk.C_R_HI)):
            tables.append(tuple(np.asarray(x, float) for x in (branch.delta, branch.force, branch.energy)))
            P[base + lo], P[base + hi] = offset, offset + branch.delta.size
            offset += branch.delta.size
    elif law.adhesive:
        P[base + wk.C_MODE] = wk.MODE_JKR
        P[base + wk.C_INV_DELTA0], P[base + wk.C_PSCALE] = law._inv_delta0, law._pscale
        P[base + wk.C_ESCALE] = law._pscale * law._delta0
    else:
        P[base + wk.C_MODE] = wk.MODE_HERTZ


def bridge_block(bridges, t0: float) -> np.ndarray:
    """The bridges' block of P (`wet_discrete_kernel.B_*`) for `bridges` (a `DiscreteBridges`), contact from t0."""
    B = np.zeros(wk.BRIDGE_PARAMS)
    B[wk.B_T0], B[wk.B_TA], B[wk.B_H1] = t0, bridges.t_a, bridges.h1
    B[wk.B_DK], B[wk.B_F0] = bridges.d_k, bridges.f0
    B[wk.B_ABORT_ON_FORM] = 0.0 if bridges.ever else 1.0
    for j, kind in enumerate(("force", "energy")):
        comp, stretch = bridges.coeffs[kind]
        B[wk.B_COEF + 6 * j: wk.B_COEF + 6 * j + 3] = comp
        B[wk.B_COEF + 6 * j + 3: wk.B_COEF + 6 * j + 6] = stretch
    return B


def bridge_state(bridges) -> np.ndarray:
    """The bridges' block of S (`wet_discrete_kernel.SB_*`) from their accepted state."""
    return np.array([bridges.s, bridges.formed, bridges.t_acc, bridges.g_acc, bridges.max_bridges,
                     1.0 if bridges.ever else 0.0])


def take_back_bridges(law, state: np.ndarray, last_accept: float) -> None:
    """The bridges' block of S back into `law.bridges`, and the law's longest contact (s)."""
    b = law.bridges
    b.s, b.formed, b.t_acc, b.g_acc = (float(x) for x in state[wk.SB_S:wk.SB_G_ACC + 1])
    b.max_bridges, b.ever = float(state[wk.SB_MAX]), bool(state[wk.SB_EVER])
    law.longest_contact = max(law.longest_contact, last_accept)


def wet_form(law, t0: float) -> CompiledLaw:
    """The compiled form of `law` (a `WetDiscreteRoller`: `law.dry` a `WetSummitRoller`, `law.bridges` its
    `DiscreteBridges`) from its present state, for a contact that began at absolute time t0 (s)."""
    summits, bridges = law.dry, law.bridges
    P = np.zeros(wk.PARAMS)
    tables: list = []
    _class_block(summits, tables, P, wk.DRY)
    _class_block(summits.wet, tables, P, wk.WET)
    P[wk.G_END_GAP], P[wk.G_LOWEST] = summits.end_gap, -summits.depth_keep
    P[wk.G_BRIDGES:] = bridge_block(bridges, t0)
    u = np.ascontiguousarray(summits.eff - summits.z_top)
    flat = [np.concatenate([t[i] for t in tables]) if tables else np.zeros(1) for i in range(3)]
    T = (u, *flat) + EMPTY_TABLES[4:]
    n = u.size
    S = np.zeros(wk.S_FLAGS + n)
    S[0] = math.inf                                   # the deepest gap of this run (the law's max_depth)
    S[wk.S_K_WET] = summits.k_wet
    S[wk.S_DET_DRY], S[wk.S_DET_WET], S[wk.S_SWITCHED] = summits.detached, summits.detached_wet, summits.switched
    S[wk.S_BRIDGES:wk.S_FLAGS] = bridge_state(bridges)
    S[wk.S_K_ATT] = summits.k_att
    S[wk.S_FLAGS:] = summits.attached[:n]
    return CompiledLaw(wk.LAW_WET_DISCRETE, P, T, S)


def take_back(law, S: np.ndarray, last_accept: float) -> None:
    """Write the kernel's history `S` back into `law` (a `WetDiscreteRoller`); last_accept: contact time (s) of
    the last accepted state."""
    summits = law.dry
    n = summits.eff.size
    summits.attached[:] = S[wk.S_FLAGS:wk.S_FLAGS + n] != 0.0
    summits.k_wet = summits.k_trial = int(S[wk.S_K_WET])
    summits.k_att = int(S[wk.S_K_ATT])
    summits.detached, summits.detached_wet = int(S[wk.S_DET_DRY]), int(S[wk.S_DET_WET])
    summits.switched = float(S[wk.S_SWITCHED])
    summits._cache_gap = None
    summits.max_contacts = max(summits.max_contacts, int(S[wk.S_MAX_CONTACTS]))
    if math.isfinite(S[0]):
        summits.max_depth = max(summits.max_depth, -float(S[0]))
        if -S[0] > summits.strip_depth:
            summits.beyond_strip = True
    take_back_bridges(law, S[wk.S_BRIDGES:wk.S_FLAGS], last_accept)
