"""What the adhesion protocol's optional legs measure, for :class:`md.workflows.adhesion.Adhesion`'s analysis: the
SAM anneal (energy and mean chain tilt, and whether they still drift), every registry's own zero-load contact, the
registries that repeat another, and the return chain (W_F out and back, their hysteresis).

A work of adhesion from a forward-only chain of short windows is a non-equilibrium work and exceeds the free
energy by the dissipated part (second law); SAM contacts are known for adhesion hysteresis (Chaudhury & Owen,
J. Phys. Chem. 97 (1993) 5122). Pulling the same windows out and back brackets it: the mean of the two directions
is the estimate, half their difference its systematic error (:func:`md.analysis.adhesion.hysteresis`).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from md import analysis as A
from md import units as U
from md.analysis.drift import linear_drift
from md.workflows.common import quantity_record
from md.workflows.plan_records import AdhesionPlanRecord


def chain_tilts_deg(ids, pos, box, axes) -> np.ndarray:
    """Mean tilt (deg) from the surface normal of the chain axes (head Si -> CH3; 0-based atom indices ``axes``)
    in every frame of atoms ``ids`` (LAMMPS ids, 1-based) at ``pos`` (frames, atoms, 3), boxes ``box`` (frames,
    >= 2). Stored positions are wrapped into the box, and a tilted C18 axis can reach further sideways than half a
    small box, so the first frame takes the minimum image (the built chains lean 15 deg) and every later frame
    the image nearest the axis of the frame before (an axis moves far less than half a box between frames)."""
    col = {int(i): k for k, i in enumerate(ids)}
    h = [col[int(a) + 1] for a in axes[:, 0]]
    e = [col[int(a) + 1] for a in axes[:, 1]]
    out, prev = [], None
    for k in range(len(pos)):
        b = np.asarray(box[k], float)[:2]
        v = np.asarray(pos[k])[e] - np.asarray(pos[k])[h]
        ref = np.zeros_like(v[:, :2]) if prev is None else prev[:, :2]
        v[:, :2] += b * np.round((ref - v[:, :2]) / b)
        prev = v
        cos = np.clip(np.abs(v[:, 2]) / np.linalg.norm(v, axis=1), 0.0, 1.0)
        out.append(float(np.degrees(np.mean(np.arccos(cos)))))
    return np.array(out)


def anneal_record(ctx, dt_fs: float) -> tuple[dict[str, Any], list[str], dict]:
    """The anneal leg's energy and mean chain tilt series, and a linear-drift test on the second half of each
    (the first half is the relaxation; the question is whether it has ended): (details, notes, curves)."""
    d = ctx.samples("anneal", False)
    t_ps = d["step"] * dt_fs * 1e-3
    half = len(t_ps) // 2
    det: dict[str, Any] = {"time_ps": t_ps.tolist(), "potential_energy_kcal": np.asarray(d["pe"]).tolist()}
    checks = {"potential_energy_kcal": linear_drift(t_ps[half:], d["pe"][half:])}
    curves = {"anneal_energy": (["step", "time_s", "potential_energy_J"],
                                np.column_stack([d["step"], U.fs_to_s(d["step"] * dt_fs),
                                                 U.kcal_per_mol_to_J(d["pe"])]))}
    axes = np.asarray(next(l.info["chain_axes"] for l in ctx.plan.legs if l.name == "anneal"), int).reshape(-1, 2)
    if len(axes):
        steps, ids, pos, box = ctx.frames("anneal")
        tilt = chain_tilts_deg(ids, pos, box, axes)
        tf = np.asarray(steps, float) * dt_fs * 1e-3
        det.update(tilt_time_ps=tf.tolist(), mean_tilt_deg=tilt.tolist())
        if len(tilt) >= 8:
            checks["mean_tilt_deg"] = linear_drift(tf[len(tf) // 2:], tilt[len(tilt) // 2:])
        curves["anneal_tilt"] = (["step", "time_s", "mean_tilt_deg"],
                                 np.column_stack([steps, U.fs_to_s(np.asarray(steps) * dt_fs), tilt]))
    det["drift_second_half"] = checks
    drifting = [k for k, c in checks.items() if c["drifting"]]
    span = f"{t_ps[-1] - t_ps[0]:.3g} ps" if len(t_ps) else "0 ps"
    text = "; ".join(f"{k}: drift {c['drift']:+.3g} +/- {c['drift_stderr']:.2g} over the second half (a drift "
                     f"beyond {c['drift_threshold']:.2g})" for k, c in checks.items())
    notes = [(f"ANNEAL STILL DRIFTING ({', '.join(drifting)}): the surfaces had not settled when the contact was "
              f"formed; lengthen sam_anneal_steps. " if drifting else "SAM anneal: no linear drift in its second half "
              "beyond the drift test's threshold (md.analysis.drift). ")
             + f"Anneal of the separated pair ({span} at T): {text}."]
    return det, notes, curves


def draw_anneal(ax, det: dict[str, Any]) -> None:
    """The anneal (``anneal_record``'s details) on one axes: potential energy against time, the mean chain tilt on
    a second axis, and over each the least-squares line of the second half that the drift test fits (dashed), so
    a reader sees whether the surfaces had settled before contact; the title says what the test concluded."""
    t = np.asarray(det["time_ps"], float)
    pe = np.asarray(det["potential_energy_kcal"], float)
    checks = det["drift_second_half"]
    ax.plot(t, pe, lw=0.6, color="C0", label="potential energy")
    _draw_fit(ax, t, pe, checks["potential_energy_kcal"], "navy")
    late = pe[len(pe) // 20:]                   # the range after the minimised start's first relaxation
    pad = 0.1 * float(np.ptp(late))
    ax.set_ylim(float(late.min()) - pad, float(late.max()) + pad)
    ax.set_xlabel("anneal time (ps)")
    ax.set_ylabel("potential energy (kcal/mol)", color="C0")
    if "mean_tilt_deg" in det:
        tt, tilt = np.asarray(det["tilt_time_ps"], float), np.asarray(det["mean_tilt_deg"], float)
        ax2 = ax.twinx()
        ax2.plot(tt, tilt, ".-", ms=2, lw=0.6, color="C1")
        if "mean_tilt_deg" in checks:
            _draw_fit(ax2, tt, tilt, checks["mean_tilt_deg"], "saddlebrown")
        ax2.set_ylabel("mean chain tilt (deg)", color="C1")
    drifting = [k for k, c in checks.items() if c["drifting"]]
    ax.set_title("second half still drifting: " + ", ".join(drifting) if drifting
                 else "second half: no drift beyond the test's threshold", fontsize=9)


def _draw_fit(ax, t, y, check: dict, color: str) -> None:
    """The drift test's line through the second half of (t, y): slope from ``check``, through the half's mean."""
    h = len(t) // 2
    th, yh = t[h:], y[h:]
    ax.plot(th, yh.mean() + check["slope"] * (th - th.mean()), "--", lw=1.6, color=color)


def registry_contacts_record(ctx, energy_separated, area_A2: float, zc: float, tail_J_m2: float) -> dict:
    """Every registry's own zero-load contact leg (``contact_rN``): dE/A against the separated leg (the static
    tail of registry 0's contact added) and the mean back height relative to registry 0's contact."""
    out = {}
    for leg in ctx.plan.legs:
        if not leg.name.startswith("contact_r"):
            continue
        con = ctx.samples(leg.name)
        w = A.energy_separation_work(con["pe"], energy_separated, area_A2)
        zs = A.timeseries_stats(con["z_back"])
        out[str(leg.info["registry"])] = {"energy_work_J_m2": w["value"] + tail_J_m2, "stderr_J_m2": w["stderr"],
                                          "back_z_minus_contact_A": zs["mean"] - zc, "back_z_stderr_A": zs["stderr"],
                                          "offset_A": leg.info["offset_A"]}
    return out


def degenerate_note(plan: AdhesionPlanRecord) -> list[str]:
    """A note naming the registries whose offset is a lattice translation of an earlier one's."""
    deg = plan.degenerate_registries
    if not deg:
        return []
    n = len(plan.registry_offsets_A)
    pairs = ", ".join(f"{r} repeats {r0} (offset {plan.registry_offsets_A[r]} A)" for r, r0 in deg)
    return [f"REGISTRIES DEGENERATE: {pairs}: the offset is a lattice translation of the slabs (lattice "
            f"{np.round(plan.surface_lattice_A, 3).tolist()} A), so {n} chains sample {n - len(deg)} distinct "
            f"registr{'y' if n - len(deg) == 1 else 'ies'}; their spread is a replicate spread, not a registry "
            f"spread (registry_sampling = 'primitive' samples the primitive cell)."]


def return_path(ctx, res, chain_rows) -> None:
    """W_F of the return chain on the outward grid (the outermost window is the turning point, shared), its
    hysteresis against the outward W_F, and W_F = the mean of the two with half the hysteresis as a systematic:
    updates the adhesion analysis's results ``res`` (quantities, curves, details, notes) in place."""
    partner = {rep: suf for suf, _d, _prev, rep in chain_rows}
    shape = (res.n_reg, len(res.suffixes))
    f_m, f_e = np.full(shape, np.nan), np.full(shape, np.nan)
    for r in range(res.n_reg):
        for k, suf in enumerate(res.suffixes):
            st = A.timeseries_stats(ctx.samples(f"pmf_r{r}_{partner.get(suf, suf)}")["fz"])
            f_m[r, k], f_e[r, k] = st["mean"], st["stderr"]
    avg = A.registry_average(f_m, f_e)
    f_back, e_back = np.asarray(avg["mean"]) + res.f_tail, np.asarray(avg["stderr"])
    ti = A.force_integration_work(res.dsep, f_back, e_back, res.area, correlation=res.rho)
    w_back, err_back = ti["value"] - res.u_tail_last * res.conv, ti["stderr"]
    if res.n_reg >= 2:
        per = [A.force_integration_work(res.d_A[r], f_m[r] + res.f_tail, f_e[r], res.area, correlation=res.rho)
               for r in range(res.n_reg)]
        err_back = max(err_back, A.registry_average([p["value"] for p in per], [p["stderr"] for p in per])["stderr"])
    h = A.hysteresis(res.wf_val, res.wf_err, w_back, err_back)
    rec = res.q["work_of_adhesion_free_energy"]
    rec.update(value=h["value"], stderr=h["stderr"], systematic_hysteresis=h["systematic"], value_out=res.wf_val,
               stderr_out=res.wf_err, value_back=w_back, stderr_back=err_back,
               kind=rec["kind"] + "; the mean of the outward and the return chain, half their hysteresis as a "
                                  "systematic error")
    res.q["adhesion_hysteresis"] = quantity_record(h["hysteresis"], h["hysteresis_stderr"], "J/m^2",
                                                   kind="W_F(out) - W_F(back): work dissipated over the out-and-back "
                                                        "path per area")
    res.curves["pmf_return"] = (["separation_m", "mean_force_N", "mean_force_stderr_N"],
                                np.column_stack([U.angstrom_to_m(res.dsep), U.kcal_per_mol_A_to_N(f_back),
                                                 U.kcal_per_mol_A_to_N(e_back)]))
    res.details["pmf_return"] = {"window": [partner.get(s, s) for s in res.suffixes],
                                 "mean_force_kcal_mol_A": f_back.tolist(), "stderr_kcal_mol_A": e_back.tolist(),
                                 "per_registry_mean_force_kcal_mol_A": f_m.tolist(), "work_J_m2": w_back,
                                 "work_stderr_J_m2": err_back, "hysteresis": h}
    res.notes.append(
        f"out and back: W_F(out) = {res.wf_val:.4f} +/- {res.wf_err:.4f}, W_F(back) = {w_back:.4f} +/- {err_back:.4f} "
        f"J/m^2 over the same windows; hysteresis {h['hysteresis']:+.4f} +/- {h['hysteresis_stderr']:.4f} J/m^2. "
        f"W_F = their mean {h['value']:.4f} +/- {h['stderr']:.4f} (stat.) +/- {h['systematic']:.4f} (half the "
        f"hysteresis, systematic) J/m^2; sigma0 and T dS come from the outward curve, z0 = 1.026 W_F / sigma0 "
        f"from this mean W_F.")
