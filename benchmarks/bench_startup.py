"""First start: a cold ``trackplan demo`` (numba compiles its kernels) and a warm one.

Run with ``python -m benchmarks startup``. Prints, for ``trackplan demo`` run as a fresh
process with an empty numba cache (``NUMBA_CACHE_DIR`` a new temporary folder, a new run
folder) and then again with that cache filled:

- wall time and CPU time (user + system of the command and every process it forked and
  waited for: the planner beside the search, the plot workers, the late-compile process);
- the CPU time numba spent compiling kernels, summed over those processes (numba's
  ``numba:compile`` events, outermost compiles only), its share of the CPU time and the
  number of outermost compiles;
- the ratios against the targets: compiling ≤ 30 s CPU, and the first ``make run`` ≤ 90 s
  wall on 2 cores, install included.

With ``TRACKPLAN_BENCH_INSTALL=1`` it also times what ``make run`` does before the demo: a
new venv, ``pip install --upgrade pip`` and ``pip install -e .`` from pip's cache, and adds
it to the cold demo's wall time; without it the 90 s target is printed against the demo
with :data:`INSTALL_WALL` for the install.

Other load on the machine inflates the wall time much more than the CPU time (both are
printed; the CPU time is the figure to compare between runs).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TARGET_COMPILE_CPU = 30.0
"""s of CPU compiling kernels in the first demo."""
TARGET_FIRST_RUN = 90.0
"""s wall of the first ``make run`` (install and demo) on 2 cores."""
INSTALL_WALL = 40.0
"""s wall of the install step of ``make run`` from a warm pip cache (38.2 s measured,
docs/benchmarks.md), used when the benchmark does not time it itself."""

PROBE = """
import os, sys, time
from numba.core import event

log = sys.argv[1]
depth = {}


class Compiles(event.Listener):
    def on_start(self, ev):
        stack = depth.setdefault(os.getpid(), [])
        stack.append(time.process_time())

    def on_end(self, ev):
        stack = depth[os.getpid()]
        cpu = time.process_time() - stack.pop()
        if not stack:  # outermost: includes the compiles it triggered
            with open(log, "a") as handle:
                handle.write(f"{os.getpid()} {cpu:.4f}\\n")


event.register("numba:compile", Compiles())
from trackplan.cli import exit_process, main

exit_process(main(sys.argv[2:]))
"""
"""Runs the command line with a listener that appends each outermost compile's CPU time."""


def _run(args: list[str], env: dict[str, str]) -> tuple[float, float, int]:
    """Wall and CPU time (user + system of the process and its waited-for children) of a
    command, s, and its exit code."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(args, check=False, capture_output=True, env=env)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    if done.returncode not in (0, 3):
        sys.stderr.write(done.stderr.decode(errors="replace"))
    return wall, cpu, done.returncode


def _demo(cache: Path, out: Path, log: Path) -> tuple[float, float, float, int]:
    """One ``trackplan demo``: wall, CPU, compile CPU (s) and the number of compiles."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    log.unlink(missing_ok=True)
    wall, cpu, _ = _run([sys.executable, "-c", PROBE, str(log), "demo", "--out", str(out)], env)
    lines = log.read_text().splitlines() if log.exists() else []
    compiles = [float(line.split()[1]) for line in lines]
    return wall, cpu, sum(compiles), len(compiles)


def _install(folder: Path) -> tuple[float, float]:
    """Wall and CPU time of ``make run``'s install step into a new venv, s."""
    venv = folder / "venv"
    python = venv / "bin" / "python"
    steps = (
        [sys.executable, "-m", "venv", str(venv)],
        [str(python), "-m", "pip", "install", "--quiet", "--upgrade", "pip"],
        [str(python), "-m", "pip", "install", "--quiet", "-e", str(ROOT)],
    )
    wall = cpu = 0.0
    for step in steps:
        step_wall, step_cpu, _ = _run(step, dict(os.environ))
        wall += step_wall
        cpu += step_cpu
    return wall, cpu


def main() -> None:
    """Print the cold and the warm demo, and their ratios against the targets."""
    with tempfile.TemporaryDirectory(prefix="trackplan-startup-") as tmp:
        folder = Path(tmp)
        install = None
        if os.environ.get("TRACKPLAN_BENCH_INSTALL", "") not in ("", "0"):
            install = _install(folder)
        cache = folder / "numba-cache"
        cache.mkdir()
        cold = _demo(cache, folder / "cold", folder / "cold.log")
        warm = _demo(cache, folder / "warm", folder / "warm.log")
    print("trackplan demo as a fresh process (CPU: user + system, its forked processes included)")
    print(f"  {'run':<34}{'wall s':>8}{'CPU s':>8}{'compiling s':>13}{'share':>7}{'compiles':>10}")
    if install is not None:
        print(f"  {'install (venv, pip, -e .)':<34}{install[0]:>8.1f}{install[1]:>8.1f}")
    for label, (wall, cpu, compiling, count) in (
        ("cold (empty numba cache)", cold),
        ("warm (cache filled by the cold run)", warm),
    ):
        share = compiling / cpu if cpu > 0 else 0.0
        print(
            f"  {label:<34}{wall:>8.1f}{cpu:>8.1f}{compiling:>13.1f}{100 * share:>6.0f}%{count:>10}"
        )
    verdict = "MET" if cold[2] <= TARGET_COMPILE_CPU else "MISSED"
    print(
        f"  compiling in the cold demo: {cold[2]:.1f} s CPU, {cold[2] / TARGET_COMPILE_CPU:.2f}× "
        f"the target ≤ {TARGET_COMPILE_CPU:g} s: {verdict}"
    )
    install_wall = install[0] if install is not None else INSTALL_WALL
    first = install_wall + cold[0]
    source = "measured" if install is not None else "INSTALL_WALL"
    verdict = "MET" if first <= TARGET_FIRST_RUN else "MISSED"
    print(
        f"  first make run: install {install_wall:.0f} s ({source}) + cold demo {cold[0]:.1f} s "
        f"= {first:.0f} s wall, {first / TARGET_FIRST_RUN:.2f}× the target "
        f"≤ {TARGET_FIRST_RUN:g} s on 2 cores: {verdict}"
    )
    print(f"  warm demo against the cold one: {warm[1] / cold[1]:.2f}× its CPU time")
    print("  (other load inflates the wall time more than the CPU time; targets: an idle machine)")


if __name__ == "__main__":
    main()
