"""Contact laws of adhesive elastic-plastic summits (`continuum.rough.plastic_summits`): a rigid flat punch and a rigid
roller on their GW mean field, and a flat punch on discrete summits, each carrying the summits' flattening from one
contact to the next.

History: the mean-field laws keep the deepest separation ever reached, d_p (the summits' flattening), and this
contact's deepest, d_c; the discrete law keeps each summit's deepest approach. The driver ends a contact at its
first turn while attached (`bound_is_final`), so a contact is one approach and one retreat, which (d, d_c, d_p)
describe exactly. Losses come from the laws' own terms (plastic work, the loops of the summits that let go), so the
driver's energy audit tests the motion against them.

Sources: C. Thornton & Z. Ning, Powder Technol. 99 (1998) 154-162; J. A. Greenwood & J. B. P. Williamson, Proc. R.
Soc. Lond. A 295 (1966) 300.
"""
from __future__ import annotations

import math

import numpy as np

from ..rough.plastic_gw_branches import BranchRollerFootprint
from ..rough.plastic_gw_kernel import S_D_C, S_D_P, law_arrays
from ..rough.plastic_summits import PlasticGWSurface, PlasticSummitLaw, RollerFootprint
from .base import ContactLaw

__all__ = ["PlasticGWPunch", "PlasticGWRoller", "PlasticSummitsPunch", "PlasticDiscreteRoller"]


class PlasticGWPunch(ContactLaw):
    """Rigid flat of nominal area A (m^2) on a `PlasticGWSurface`; gap = d - z_max (m) above the tallest summit.

    The deepest separation ever, d_p, outlives a contact (`reset` keeps it, `forget_history` clears it), so a
    second impact meets flattened summits. Losses from the law's own terms: plastic work W_p(d_p) and the loops
    of the summits that let go."""

    name = "plastic_gw_punch"
    has_history = True
    bound_is_final = True   # the driver ends a contact at its first turn while attached (one approach, one retreat)
    #: run contacts in the compiled contact phase where the surface has compiled sums (`compiled`); False keeps them
    #: on the driver's Python stepper calling the same sums (the reference the compiled phase is tested against)
    compiled_contact = True

    def __init__(self, surface: PlasticGWSurface, area: float):
        self.surface, self.area = surface, float(area)
        #: tallest summit above the summits' mean plane (m) and their height rms (m), as the rough rollers give them
        self.z_top, self.sigma = surface.z_top, surface.sigma
        self.forget_history()

    def forget_history(self) -> None:
        self._d_p = self.surface.z_top          # no summit met yet
        self.impacts = 0
        self.reset()

    def reset(self) -> None:
        self._d_c = math.inf
        self._d_0 = self._d_p                   # the deepest separation before this contact
        self._w0 = self.surface.plastic_work(self._d_p)

    @property
    def touch_gap(self) -> float:
        """Gap (m) at which the contact starts: the tallest summit's reach (0 for JKR summits, which exert nothing
        before they touch)."""
        sep = self.surface.touch_separation(self._d_p)
        return 0.0 if sep is None else self._d_p + sep - self.surface.z_top

    def _trial(self, gap):
        d = self.surface.z_top + gap
        return d, min(self._d_c, d), min(self._d_p, d)

    def force(self, gap):
        return self.area * self.surface.state(*self._trial(gap))[0]

    def stiffness(self, gap):
        h = 1e-7 * self.surface.sigma
        return (self.force(gap - h) - self.force(gap + h)) / (2.0 * h)

    def stored_energy(self, gap):
        return self.area * self.surface.state(*self._trial(gap))[1]

    def dissipated(self, gap):
        d, d_c, d_p = self._trial(gap)
        s = self.surface
        return self.area * (s.plastic_work(d_p) - self._w0 + s.jumps(d, d_c, d_p, self._d_0))

    def release_gap(self):
        s = self.surface
        return self._d_p + s.release_separation(self._d_c, self._d_p) - s.z_top

    def on_release(self):
        s = self.surface
        return self.area * (s.plastic_work(self._d_p) - self._w0 + s.jumps(math.inf, self._d_c, self._d_p, self._d_0))

    def accept(self, gap):
        d, self._d_c, self._d_p = self._trial(gap)
        self.surface.check_depth(self._d_p)

    def length_scale(self, mass, speed):
        return max(0.1 * self.surface.sigma, self.surface.delta_c)

    def compiled(self, t0: float):
        """The contact's compiled form (`continuum.rough.plastic_gw_kernel.law_value`, kernel kind `LAW_PLASTIC_GW`)
        on a surface whose sums are compiled (`PlasticBranchGWSurface.compiled`: Maugis-Dugdale or DMT summits with
        tables); None for the closed-form JKR surface or with `compiled_contact` off (the Python stepper runs it)."""
        if not (self.compiled_contact and self.surface.compiled):
            return None
        from ..numerics import kernel_laws as kl
        from ..numerics.compiled_contact import CompiledLaw
        P, T, S = law_arrays(self.surface, self.area, self._d_c, self._d_p, self._d_0, self._w0)
        return CompiledLaw(kl.LAW_PLASTIC_GW, P, T, S)

    def compiled_commit(self, state, last_accept: float) -> None:
        """Take back a compiled contact's history (d_c, d_p): what `accept` left after its last accepted state."""
        self._d_c, self._d_p = float(state[S_D_C]), float(state[S_D_P])

    def diagnostics(self):
        """The deepest state reached (first contact's maximum approach, where the most summits hold): its summits in
        contact and nominal pressure on the axis, the plastic work so far, and that the summits are plastic."""
        s, d = self.surface, self._d_p
        contacts = self.area * s.state(d, d, d)[2] if d < s.z_top else 0.0
        return {"deepest_separation": d, "plastic_work": self.area * s.plastic_work(d), "max_contacts": contacts,
                "max_nominal_pressure": s.axis_state(d, d, d)[0] if d < s.z_top else 0.0, "plastic_summits": True}

    def describe(self):
        s = self.surface
        return {"name": self.name, "area": self.area, "sigma": s.sigma, "density": s.density, "z_top": s.z_top,
                "z_max": s.z_top,           # the tallest summit's height (m), as the elastic rough laws record it
                "summit_law": s.law.describe(), "source": "Greenwood & Williamson (1966) mean field of Thornton & "
                "Ning (1998) summits, history (d, d_c, d_p)"}


class PlasticGWRoller(PlasticGWPunch):
    """Rigid roller of radius R and length l (m) on the mean field of plastic summits over a rigid substrate
    (`RollerFootprint` for Thornton-Ning JKR summits, `BranchRollerFootprint` for Thornton-Ning's construction on
    Maugis-Dugdale or DMT summits, `PlasticBranchSummitLaw`); gap = d - z_max on the roller's axis. Same history
    and losses as `PlasticGWPunch`."""

    name = "rough_roller_gw_plastic_rigid"

    def __init__(self, law, sigma: float, density: float, z_max: float, radius: float, length: float):
        footprint = RollerFootprint if isinstance(law, PlasticSummitLaw) else BranchRollerFootprint
        super().__init__(footprint(law, sigma, density, z_max, radius, length), 1.0)

    def describe(self):
        s = self.surface
        return {**super().describe(), "name": self.name, "roller_radius": s.roller_radius, "length": s.length,
                "source": f"Greenwood & Williamson (1966) mean field of Thornton & Ning (1998) "
                          f"{s.law.describe()['name']} summits under a rigid roller over a rigid substrate, history "
                          "(h, h_c, h_p) on its axis"}


class PlasticSummitsPunch(ContactLaw):
    """Rigid flat on discrete adhesive elastic-plastic summits of heights z (m); gap = d - max(z) (m).

    The summit law is `PlasticSummitLaw` (JKR, closed form) or `PlasticBranchSummitLaw` (Thornton-Ning's
    construction on any law of the Tabor range). Each summit carries its deepest approach (hence R_p and delta_p)
    into later contacts; `forget_history` returns them to virgin summits. A summit jumps onto its retreat branch at
    delta_p + delta_in(R_p), lets go at delta_p + delta_out(R_p), and otherwise exerts its approach branch's force
    (the Maugis-Dugdale attraction before contact; none for JKR). The jumps book U_A - U_R (in) and U_R - U_A (out),
    whose sum is the loop of the R_p curve.

    Cost: the summits are kept sorted by height, and a state is evaluated on the prefix that can pull or be
    attached (delta_i >= -max(reach, stretch), since delta_p >= 0), so a call costs O(summits within reach)."""

    name = "plastic_summits_punch"
    has_history = True
    bound_is_final = True

    def __init__(self, law, heights):
        self.law = law
        self.heights = np.sort(np.asarray(heights, float))[::-1].copy()      # descending
        self._neg = -self.heights                                            # ascending, for searchsorted
        self.z_top = float(self.heights[0])
        self._below = self.heights - self.z_top                              # e_i - z_top (m), the kernel's T[0]
        self._approach_reach = float(law.approach_reach)
        self.touch_gap = self._approach_reach    # the tallest summit's attraction starts here
        self.forget_history()

    def forget_history(self) -> None:
        self.delta_max = np.zeros_like(self.heights)      # 0 < delta_y: virgin summits
        self.max_contacts = 0
        self._reach = max(self._approach_reach, float(-self.law.jump_out(np.array([self.law.radius]))[0]))
        self._w_total = 0.0                               # plastic work of the accepted state (J)
        self.reset()

    def reset(self) -> None:
        self._attached = np.zeros(self.heights.size, bool)
        self._met = np.zeros(self.heights.size, bool)
        self._w0 = self._w_total
        self._loops = 0.0
        self._memo = None

    def _prefix(self, gap) -> int:
        """Summits that can pull or be attached at gap: delta_i = z_i - z_top - gap >= -reach."""
        return int(np.searchsorted(self._neg, -(self.z_top + gap - self._reach), side="right"))

    def _trial(self, gap):
        """(k, delta, attached, deepest approach, jumps booked now, plastic work change) on the first k summits;
        summits beyond k keep their accepted state and are free."""
        if self._memo is not None and self._memo[0] == gap:
            return self._memo[1]
        law = self.law
        k = max(self._prefix(gap), int(np.flatnonzero(self._attached)[-1]) + 1 if self._attached.any() else 0)
        delta = self.heights[:k] - self.z_top - gap
        dm0, held = self.delta_max[:k], self._attached[:k]
        r_p, d_p = law.flattening(dm0)
        eps = delta - d_p
        attached = (eps >= law.jump_in(r_p)) | (held & (eps > law.jump_out(r_p)))
        lost, gained = held & ~attached, attached & ~held
        dm = np.where(attached, np.maximum(dm0, delta), dm0)
        grew = dm > dm0
        jumps = float(np.sum(law.out_switch(r_p[lost]))) if lost.any() else 0.0
        if gained.any():
            jumps += float(np.sum(law.in_switch(r_p[gained])))
        dw = (float(np.sum(law.plastic_work(dm[grew])) - np.sum(law.plastic_work(dm0[grew])))
              if grew.any() else 0.0)
        out = (k, delta, attached, dm, jumps, dw)
        self._memo = (gap, out)
        return out

    def _values(self, gap):
        k, delta, att, dm, jumps, dw = self._trial(gap)
        if k == 0:
            return 0.0, 0.0, jumps, dw
        f, en = self.law.state(delta, dm, att)
        return float(np.sum(f)), float(np.sum(en)), jumps, dw

    def force(self, gap):
        return self._values(gap)[0]

    def stiffness(self, gap):
        h = 1e-9 * self.law.radius
        return (self.force(gap - h) - self.force(gap + h)) / (2.0 * h)

    def stored_energy(self, gap):
        return self._values(gap)[1]

    def dissipated(self, gap):
        _, _, jumps, dw = self._values(gap)
        return self._w_total + dw - self._w0 + self._loops + jumps

    def _rows(self, law):
        """Each summit's accepted state on `law`, (5, n): R_p0, delta_p0, W_p(dm0), delta_in(R_p0), delta_out(R_p0)
        (the compiled tables' block 5). Between contacts only the summits whose deepest approach changed are
        evaluated again (each row is elementwise in delta_max, so a summit's values do not depend on which others
        are evaluated with it); an unyielded summit takes beta's values."""
        return self._row_cache(law)[2]

    def _row_cache(self, law):
        """(law, delta_max the rows were evaluated at, rows, beta's column, [index of max(z_i - delta_p0,i)])."""
        caches = self.__dict__.setdefault("_row_caches", {})
        cache = caches.get(id(law))
        if cache is None or cache[0] is not law or cache[1].shape != self.delta_max.shape:
            base = np.array([law.radius])
            virgin = np.array([law.radius, 0.0, 0.0, law.jump_in(base)[0], law.jump_out(base)[0]])
            n = self.delta_max.size
            cache = (law, np.full(n, math.nan), np.empty((5, n)), virgin, [-1])     # every summit evaluated first
            caches[id(law)] = cache
        _, seen, rows, virgin, top = cache
        changed = np.flatnonzero(self.delta_max != seen)
        if changed.size:
            dm = self.delta_max[changed]
            yielded = dm > law.yield_approach
            rows[:, changed] = virgin[:, None]
            if yielded.any():
                idx, dmy = changed[yielded], dm[yielded]
                r0, dp0 = law.flattening(dmy)
                rows[0, idx], rows[1, idx], rows[2, idx] = r0, dp0, law.plastic_work(dmy)
                rows[3, idx], rows[4, idx] = law.jump_in(r0), law.jump_out(r0)
            seen[changed] = dm
            # the highest flattened summit: kept by comparison with the changed ones unless it is one of them
            i = top[0]
            if i < 0 or np.any(changed == i):
                top[0] = int(np.argmax(self.heights - rows[1]))
            else:
                j = int(np.argmax(self.heights[changed] - rows[1, changed]))
                if self.heights[changed[j]] - rows[1, changed[j]] > self.heights[i] - rows[1, i]:
                    top[0] = int(changed[j])
        return cache

    def _release_gap_of(self, law, cache=None) -> float:
        """`release_gap` with every summit on `law` (`cache`: its `_row_cache`, where the caller has it)."""
        stretch = law.max_stretch
        _, _, rows, _, top = self._row_cache(law) if cache is None else cache
        met = np.flatnonzero(self._met)
        if stretch is not None and not met.size:
            # before any summit is met in this contact: a bound for the whole contact (R_p may still grow), where
            # every summit has let go and is out of reach (the compiled form runs to it)
            i = top[0]
            return float(self.heights[i] - rows[1, i]) - self.z_top + stretch
        if met.size:
            held = float(np.max(self.heights[met] - rows[1, met] - rows[4, met])) - self.z_top
        else:
            held = float(np.max(self.heights - rows[1] - rows[4])) - self.z_top
        return max(held, self._approach_reach) if self._approach_reach > 0.0 else held

    def release_gap(self):
        return self._release_gap_of(self.law)

    def on_release(self):
        held = self._attached
        r_p = self.law.flattening(self.delta_max[held])[0]
        return self._w_total - self._w0 + self._loops + float(np.sum(self.law.out_switch(r_p)))

    def accept(self, gap):
        k, _, att, dm, jumps, dw = self._trial(gap)
        self._loops += jumps
        self._w_total += dw
        self._attached[:k], self.delta_max[:k] = att, dm
        self._met[:k] |= att
        self._memo = None
        self.max_contacts = max(self.max_contacts, int(att.sum()))
        if att.any():
            self._reach = max(self._reach, float(np.max(-self.law.jump_out(self.law.flattening(dm[att])[0]))))

    def length_scale(self, mass, speed):
        return max(self._reach, self._approach_reach)

    #: effective heights below which summits were not kept (m below the datum; the punch keeps all)
    _lowest = -math.inf

    def compiled(self, t0: float):
        """The contact's compiled form (`continuum.rough.plastic_kernel`, `LAW_PLASTIC`) for summits of a
        `PlasticBranchSummitLaw`; None for the closed-form JKR law (the Python stepper runs it)."""
        if not self.law.compiled_form:
            return None
        from ..numerics import kernel_laws as kl
        from ..numerics.compiled_contact import CompiledLaw
        from ..rough.plastic_kernel import compiled_tables
        cache = self._row_cache(self.law)
        P, T = compiled_tables(self.law, self._below, self.delta_max, self._release_gap_of(self.law, cache),
                               self.law.max_stretch, self._lowest, rows=cache[2])
        return CompiledLaw(kl.LAW_PLASTIC, P, T, np.array([math.inf, 0.0, 0.0, 0.0, 0.0]))

    def compiled_commit(self, state, last_accept: float) -> None:
        """Take back a compiled contact: its deepest gap h_min fixes which summits jumped in and how deep each went
        (`continuum.rough.plastic_kernel`); their plastic work and jump-in terms are booked as `accept` would."""
        h_min = float(state[0])
        self.max_contacts = max(self.max_contacts, int(state[2]))
        if not math.isfinite(h_min):
            return
        law = self.law
        rows = self._rows(law)
        # the summits the contact could reach (delta_p >= 0 and delta_in >= -reach): a prefix of the sorted heights
        k = int(np.searchsorted(self._neg, -(self.z_top + h_min - law.max_stretch), side="right"))
        dm0 = self.delta_max[:k]
        deep = self._below[:k] - h_min
        jumped = deep - rows[1, :k] >= rows[3, :k]
        grew = jumped & (deep > dm0)
        if grew.any():
            self._w_total += float(np.sum(law.plastic_work(deep[grew])) - np.sum(rows[2, :k][grew]))
        if jumped.any():
            self._loops += float(np.sum(law.in_switch(rows[0, :k][jumped])))
            self.delta_max[:k][grew] = deep[grew]
        self._met[:k] |= jumped
        self._attached[:] = False
        self._attached[:k] = jumped
        self._memo = None

    def diagnostics(self):
        yielded = self.delta_max > self.law.yield_approach
        r_p, d_p = self.law.flattening(self.delta_max[yielded])
        out = {"summits_yielded": int(np.sum(yielded)), "max_contacts": self.max_contacts, "plastic_summits": True,
               "plastic_work": self._w_total, "plastic_radius": r_p.tolist(), "plastic_approach": d_p.tolist()}
        if yielded.any():
            out["max_contact_radius_ratio"] = float(np.max(self.law.range_radius_ratio(self.delta_max[yielded])))
        return out

    def describe(self):
        return {"name": self.name, "summits": int(self.heights.size), "summit_law": self.law.describe(),
                "source": "Thornton & Ning (1998) on each summit, each carrying its flattening"}


class PlasticDiscreteRoller(PlasticSummitsPunch):
    """Rigid roller on a realisation of individual Thornton-Ning summits over a rigid substrate.

    Under a rigid roller summit i at x_i has approach delta_i = e_i - z_top - gap with its effective height
    e_i = z_i - x_i^2/2R (`continuum.laws.discrete_roller`), so the roller is the flat punch on the effective
    heights. `effective_heights` are those the elastic discrete roller kept (e_i >= z_top - depth_keep, m); a
    contact deeper than depth_keep is refused (summits below the cut would be missing)."""

    name = "rough_roller_discrete_plastic"

    def __init__(self, law: PlasticSummitLaw, effective_heights, sigma: float, depth_keep: float):
        super().__init__(law, effective_heights)
        self.sigma, self.depth_keep = float(sigma), float(depth_keep)
        self._lowest = -self.depth_keep

    def accept(self, gap):
        if -gap > self.depth_keep:
            raise ValueError(f"discrete plastic roller: approach {-gap:.3g} m beyond the kept summits' depth "
                             f"{self.depth_keep:.3g} m")
        super().accept(gap)

    def describe(self):
        return {**super().describe(), "name": self.name, "depth_keep": self.depth_keep,
                "source": "Thornton & Ning (1998) on each summit of the realisation, each carrying its flattening; "
                          "rigid roller and substrate (effective heights z_i - x_i^2/2R)"}
