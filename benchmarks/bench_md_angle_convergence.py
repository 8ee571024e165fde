"""Is the water contact angle on OTS converged in run length and droplet size? (reads results, runs no MD)

    .venv/bin/python benchmarks/bench_md_angle_convergence.py [--png PATH] [--json PATH]

Reads the committed quick OTS droplets under `inputs/md/results/` -- `contact_angle_ots-quick` (R0 = 2 nm, 60 ps
sampled), `contact_angle_ots_long-quick` (R0 = 2 nm, 150 ps) and `contact_angle_ots_large-quick` (R0 = 3 nm,
150 ps) -- and `wsl_ots-quick` (W_SL by thermodynamic integration, no droplet). For each droplet: its block angles
against time (as simulated, and with the run's water-TraPPE tail ΔW_SL added, cos θ = cos θ_sim + ΔW/γ_lv, as
`contact_angle` is), the run's angle with its stderr, the drift test, and the mean of the blocks after the
first. The figure puts the series of both sizes beside the TI band. Accuracy and cost, not speed: the wall time
each run took is printed from its result.json.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from md.analysis import angle_from_work_of_adhesion_sl  # noqa: E402

RESULTS = ROOT / "inputs" / "md" / "results"
DROPLETS = ("contact_angle_ots-quick", "contact_angle_ots_long-quick", "contact_angle_ots_large-quick")
TI = "wsl_ots-quick"


def _tail_corrected(theta_sim_deg: np.ndarray, dw: float, gamma: float) -> np.ndarray:
    """The block angles with the tail added to W_SL = gamma (1 + cos theta), inverted by the project's Young-Dupre."""
    w = gamma * (1.0 + np.cos(np.radians(theta_sim_deg))) + dw
    return np.array([angle_from_work_of_adhesion_sl(x, 0.0, gamma)["theta_deg"] for x in w])


def droplet_summary(folder: Path) -> dict:
    res = json.loads((folder / "result.json").read_text())
    q, d, s = res["quantities"], res["details"], res["settings"]
    gamma = float(q["surface_tension_lv"]["value"])
    dw = float(q["dispersion_tail_work_sl"]["value"])
    blocks = np.asarray(d["block_angles_deg"], float)
    times = np.asarray(d["block_times_ns"], float)
    corrected = _tail_corrected(blocks, dw, gamma)
    later = corrected[1:]
    return {
        "run": folder.name, "run_hash": res["run_hash"][:16], "atoms": res["n_atoms"],
        "R0_nm": float(s["droplet_radius_A"]) / 10.0,
        "sampled_ps": int(s["sample_steps"]) * float(res["timestep_fs"]) / 1000.0,
        "theta_deg": float(q["contact_angle"]["value"]), "stderr_deg": float(q["contact_angle"]["stderr"]),
        "theta_as_simulated_deg": float(q["contact_angle_as_simulated"]["value"]),
        "tail_dW_J_m2": dw,
        "block_times_ns": times.tolist(), "block_angles_sim_deg": blocks.tolist(),
        "block_angles_deg": corrected.tolist(),
        "drift_deg_per_ns": float(d["drift"]["slope"]), "drift_stderr": float(d["drift"]["stderr"]),
        "drifting": bool(d["drift"]["drifting"]),
        "after_first_block_deg": float(later.mean()) if later.size else None,
        "after_first_block_stderr": float(later.std(ddof=1) / math.sqrt(later.size)) if later.size > 1 else None,
        "shape_statistical_inefficiency_frames": d["blocks"].get("shape_statistical_inefficiency_frames"),
        "n_frames": d["n_frames"], "dynamics_wall_min": float(res["wall_s"]["dynamics"]) / 60.0,
    }


def ti_summary(folder: Path) -> dict:
    res = json.loads((folder / "result.json").read_text())
    q = res["quantities"]
    return {"run": folder.name, "run_hash": res["run_hash"][:16],
            "theta_deg": float(q["contact_angle"]["value"]), "stderr_deg": float(q["contact_angle"]["stderr"]),
            "work_of_adhesion_sl_J_m2": float(q["work_of_adhesion_sl"]["value"])}


def draw(rows: list[dict], ti: dict, path: Path) -> None:
    from matplotlib.figure import Figure  # noqa: PLC0415
    fig = Figure(figsize=(6.4, 4.0))
    ax = fig.add_subplot()
    lo, hi = ti["theta_deg"] - ti["stderr_deg"], ti["theta_deg"] + ti["stderr_deg"]
    ax.axhspan(lo, hi, color="0.85", label=f"W_SL by TI: {ti['theta_deg']:.1f} ± {ti['stderr_deg']:.1f}°")
    for k, y in enumerate((105.0, 120.0)):
        ax.axhline(y, color="0.5", ls="--", lw=0.8, label="acceptance window 105–120°" if k == 0 else None)
    styles = {"contact_angle_ots-quick": ("C0", "o", ":"), "contact_angle_ots_long-quick": ("C0", "s", "-"),
              "contact_angle_ots_large-quick": ("C3", "^", "-")}
    for r in rows:
        c, m, ls = styles.get(r["run"], ("k", "x", "-"))
        t = np.asarray(r["block_times_ns"]) * 1e3
        ax.plot(t, r["block_angles_deg"], marker=m, ls=ls, color=c,
                label=f"R0 = {r['R0_nm']:g} nm, {r['sampled_ps']:.0f} ps: {r['theta_deg']:.1f} ± {r['stderr_deg']:.1f}°"
                      + (" (drifting)" if r["drifting"] else ""))
    ax.set_xlabel("block centre (ps after the droplet was placed)")
    ax.set_ylabel("contact angle on OTS (deg, with the dispersion tail)")
    ax.set_title("SPC/E on OTS, quick droplets: block angles against time", fontsize=10)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--png", type=Path, help="write the figure here")
    p.add_argument("--json", type=Path, help="write the numbers here")
    a = p.parse_args(argv)
    rows = [droplet_summary(RESULTS / n) for n in DROPLETS if (RESULTS / n / "result.json").exists()]
    ti = ti_summary(RESULTS / TI)
    print(f"{'run':32s} {'R0':>4s} {'ps':>5s} {'theta':>13s} {'drift deg/ns':>14s} {'after 1st':>13s} {'wall min':>8s}")
    for r in rows:
        after = (f"{r['after_first_block_deg']:.1f} ± {r['after_first_block_stderr']:.1f}"
                 if r["after_first_block_stderr"] is not None else "-")
        print(f"{r['run']:32s} {r['R0_nm']:4.1f} {r['sampled_ps']:5.0f} {r['theta_deg']:6.1f} ± {r['stderr_deg']:4.1f} "
              f"{r['drift_deg_per_ns']:+7.0f} ± {r['drift_stderr']:4.0f}{'*' if r['drifting'] else ' '} {after:>13s} "
              f"{r['dynamics_wall_min']:8.1f}")
        print("    blocks (tail-corrected):", " ".join(f"{x:.1f}" for x in r["block_angles_deg"]),
              " at", " ".join(f"{1e3 * t:.0f}" for t in r["block_times_ns"]), "ps")
    print(f"{'TI (' + ti['run'] + ')':32s} {'':4s} {'':5s} {ti['theta_deg']:6.1f} ± {ti['stderr_deg']:4.1f}")
    if a.json:
        a.json.write_text(json.dumps({"droplets": rows, "ti": ti}, indent=1) + "\n")
    if a.png:
        draw(rows, ti, a.png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
