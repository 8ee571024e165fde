"""The compiled form of plastic summits with a bridge each (`continuum.laws.wet_plastic_summits`) after t_a: its
parameters, tables and history as `continuum.numerics.wet_plastic_kernel` reads them (in the plastic mode of
`continuum.numerics.wet_discrete_kernel.LAW_WET_DISCRETE`), and the history taken back.

As for elastic summits (`continuum.laws.wet_summits_compiled`): before t_a the law runs the dry plastic kernel, stopped
at t_a; the driver samples and accepts the state at t_a in Python, then `wet_plastic_form` hands the contact on with
every book of the Python law (attached, met flags and deepest approach of each summit, bridged prefix, plastic work,
loops, switch and formation work, the bridges' offset and clock), and `take_back` writes the kernel's history back.
Both classes must be `PlasticBranchSummitLaw`s (JKR Thornton-Ning summits have no compiled form: None).
"""
from __future__ import annotations

import math

import numpy as np

from ..numerics import wet_discrete_kernel as wk
from ..numerics import wet_plastic_kernel as wp
from ..numerics.compiled_contact import CompiledLaw
from ..rough.plastic_kernel import _law_tables
from .wet_summits_compiled import bridge_block, bridge_state, take_back_bridges


def wet_plastic_form(law, t0: float) -> CompiledLaw | None:
    """The compiled form of `law` (a `WetPlasticDiscreteRoller`: `law.dry` a `WetPlasticSummits`, `law.bridges`
    its `DiscreteBridges`) from its present state, for a contact that began at absolute time t0 (s); None where a
    class has no compiled form or the bridges' summits are not the law's."""
    s, bridges = law.dry, law.bridges
    if not (s.law.compiled_form and s.wet.compiled_form):
        return None
    u = np.ascontiguousarray(s.heights - s.z_top)
    src = bridges.source
    if u.size != src.eff.size or not np.array_equal(u, src.eff - src.z_top):
        return None
    base = wk.PARAMS
    P = np.zeros(base + wp.EXTRA)
    P[wk.DRY + wk.C_MODE] = wk.MODE_PLASTIC
    P[wk.G_BRIDGES:wk.G_BRIDGES + wk.BRIDGE_PARAMS] = bridge_block(bridges, t0)
    P[base + wp.W0], P[base + wp.LOWEST] = s._w0, s._lowest
    flat: list = [[], [], []]
    infos, rows = [], []
    counts = [0, 0, 0]
    for block, cls in ((wp.DRY_BLOCK, s.law), (wp.WET_BLOCK, s.wet)):
        Pl, (d, r_p, d_p, info, tab) = _law_tables(cls)
        c = base + block
        P[c:c + Pl.size] = Pl
        P[c + wp.CB_F_LO], P[c + wp.CB_F_HI] = counts[0], counts[0] + d.size
        P[c + wp.CB_I_LO], P[c + wp.CB_I_HI] = counts[1], counts[1] + info.size
        P[c + wp.CB_R_LO], P[c + wp.CB_R_HI] = counts[2], counts[2] + tab.shape[0]
        for j, x in enumerate((d, r_p, d_p)):
            flat[j].append(x)
        infos.append(info)
        rows.append(tab)
        counts = [counts[0] + d.size, counts[1] + info.size, counts[2] + tab.shape[0]]
    width = max(t.shape[1] for t in rows)
    tab = np.zeros((counts[2], width))
    r0 = 0
    for t in rows:
        tab[r0:r0 + t.shape[0], :t.shape[1]] = t
        r0 += t.shape[0]
    spare = np.zeros(1)
    T = (u, *(np.ascontiguousarray(np.concatenate(x)) for x in flat), np.ascontiguousarray(np.concatenate(infos)),
         spare, spare, tab)
    n = u.size
    S = np.zeros(wp.S_FLAGS + 3 * n)
    S[0] = math.inf                                   # the deepest gap of this run
    S[wp.S_K_WET] = s.k_wet
    S[wp.S_LOOPS], S[wp.S_W_TOTAL], S[wp.S_SWITCHED] = s._loops, s._w_total, s.switched
    S[wp.S_K_ATT] = int(np.flatnonzero(s._attached)[-1]) + 1 if s._attached.any() else 0
    S[wk.S_BRIDGES:wk.S_FLAGS] = bridge_state(bridges)
    S[wp.S_REACH] = s._reach
    S[wp.S_FLAGS:wp.S_FLAGS + n] = s._attached
    S[wp.S_FLAGS + n:wp.S_FLAGS + 2 * n] = s.delta_max
    S[wp.S_FLAGS + 2 * n:] = s._met
    return CompiledLaw(wk.LAW_WET_DISCRETE, P, T, S)


def take_back(law, S: np.ndarray, last_accept: float) -> None:
    """Write the kernel's history `S` back into `law` (a `WetPlasticDiscreteRoller`); last_accept: contact time (s)
    of the last accepted state."""
    s = law.dry
    n = s.heights.size
    s._attached[:] = S[wp.S_FLAGS:wp.S_FLAGS + n] != 0.0
    s.delta_max[:] = S[wp.S_FLAGS + n:wp.S_FLAGS + 2 * n]
    s._met[:] = S[wp.S_FLAGS + 2 * n:wp.S_FLAGS + 3 * n] != 0.0
    s.k_wet = s.k_trial = int(S[wp.S_K_WET])
    s._wet_seen = s._wet_seen or s.k_wet > 0
    s._loops, s._w_total, s.switched = float(S[wp.S_LOOPS]), float(S[wp.S_W_TOTAL]), float(S[wp.S_SWITCHED])
    s._reach = float(S[wp.S_REACH])
    s.max_contacts = max(s.max_contacts, int(S[wk.S_MAX_CONTACTS]))
    s._memo = None
    take_back_bridges(law, S[wk.S_BRIDGES:wk.S_FLAGS], last_accept)
