"""Cold compile of the contact kernel: one process against the two-part warm-up (`continuum.numerics.kernel_warmup`).

    python benchmarks/bench_kernel_compile.py [--json FILE]

Each case runs in fresh processes on an empty numba cache folder of its own (NUMBA_CACHE_DIR under a temporary
folder, so nothing cached is touched):

- `one process`: `compiled_contact.warm_up()` in one process, as each pytest-xdist worker compiled it on a cold cache;
  CPU seconds and the number of compiled specialisations (numba's compile events);
- `two-part warm-up`: `python -m continuum.numerics.kernel_warmup` (its two parts at once): wall seconds and the CPU
  of the parts (children);
- `load after the warm-up`: `warm_up()` in a fresh process on the warmed folder: CPU seconds and specialisations
  compiled there (0 where the warm-up compiled what a contact uses).

The machine's load average is recorded at the start and the end (the CPU seconds grow with a busy machine too).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

CHILD = r"""
import json, sys, time
from numba.core import event
compiles = []
class Count(event.Listener):
    def on_start(self, e): pass
    def on_end(self, e):
        d = e.data["dispatcher"]
        compiles.append(f"{d.py_func.__module__}.{d.py_func.__qualname__}")
event.register("numba:compile", Count())
from continuum.numerics.compiled_contact import warm_up
warm_up()
print(json.dumps({"cpu_s": time.process_time(), "compiles": len(compiles), "functions": len(set(compiles))}))
"""


def _child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _run(cmd: list[str], cache: str) -> tuple[float, float, str]:
    """(wall s, CPU s of the process and its children, stdout) of one command on the cache folder `cache`."""
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "NANOIMPACT_USER_NUMBA_CACHE_DIR")}
    env["NUMBA_CACHE_DIR"] = cache
    cpu0, t0 = _child_cpu(), time.monotonic()
    out = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True).stdout
    return time.monotonic() - t0, _child_cpu() - cpu0, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--json", help="write the numbers to this file")
    args = parser.parse_args()
    load0 = os.getloadavg()[0]
    rows = {}
    with tempfile.TemporaryDirectory() as one, tempfile.TemporaryDirectory() as two:
        wall, cpu, out = _run([sys.executable, "-c", CHILD], one)
        rows["one process"] = {"wall_s": wall, "cpu_s": cpu, **json.loads(out.splitlines()[-1])}
        wall, cpu, _ = _run([sys.executable, "-m", "continuum.numerics.kernel_warmup"], two)
        rows["two-part warm-up"] = {"wall_s": wall, "cpu_s": cpu}
        wall, cpu, out = _run([sys.executable, "-c", CHILD], two)
        rows["load after the warm-up"] = {"wall_s": wall, "cpu_s": cpu, **json.loads(out.splitlines()[-1])}
    result = {"load_average_start": load0, "load_average_end": os.getloadavg()[0], "cases": rows}
    for name, row in rows.items():
        print(f"{name:24s} " + "  ".join(f"{k} {v:.1f}" if isinstance(v, float) else f"{k} {v}"
                                         for k, v in row.items()))
    print(f"load average {load0:.2f} at the start, {result['load_average_end']:.2f} at the end")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(result, fh, indent=1)


if __name__ == "__main__":
    main()
