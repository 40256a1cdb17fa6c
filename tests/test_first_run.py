"""A first run compiles each kernel once (docs/benchmarks.md, "First run").

numba compiles a version of a kernel per writable flag of each array argument and per
constant passed from compiled code; these checks call the kernels' callers the ways a run
does (fresh and read-only inputs, a robot unpickled in a worker) and count the versions.
"""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from trackplan._kernels import read_only
from trackplan.cli import warmup
from trackplan.forking import can_fork
from trackplan.robots import _kernels as robot_kernels
from trackplan.robots.builtin import puma560
from trackplan.robots.families import _opw_kernels as family_kernels
from trackplan.robots.families import ik_family
from trackplan.robots.kinematics import axis_frames, forward_kinematics, joint_frames


def test_read_only_is_a_view_of_a_writable_array_and_the_array_itself_otherwise() -> None:
    array = np.arange(6.0).reshape(2, 3)
    view = read_only(array)
    assert not view.flags.writeable
    assert np.shares_memory(view, array)
    assert array.flags.writeable  # the caller's array is left as it was
    assert read_only(view) is view


def test_kinematics_of_an_unpickled_robot_compile_no_second_version() -> None:
    robot = puma560()
    q = np.zeros((3, robot.n_dof))
    forward_kinematics(robot, q)
    joint_frames(robot, q)
    family = ik_family(robot)
    T = forward_kinematics(robot, q)
    family.solve_flat(T)
    counts = [
        len(kernel.signatures)
        for kernel in (robot_kernels.fk_flat, robot_kernels.frames_flat, family_kernels.opw_solve)
    ]
    copy = pickle.loads(pickle.dumps(robot))  # as the planner forked beside a search gets it
    chain, _ = copy.kernel_chain
    assert chain.flags.writeable
    frozen_q = read_only(q)
    forward_kinematics(copy, q)
    forward_kinematics(robot, frozen_q)
    joint_frames(copy, frozen_q)
    axis_frames(robot, q)
    ik_family(copy).solve_flat(read_only(T))
    assert [
        len(kernel.signatures)
        for kernel in (robot_kernels.fk_flat, robot_kernels.frames_flat, family_kernels.opw_solve)
    ] == counts


COMPILE_WRITER = """
import numpy as np
from trackplan._kernels import read_only
from trackplan.io._kernels import _write_text
from trackplan.io.csv_table import format_table
text = format_table(np.array([[0.1, -2.5e-300], [3.0, np.pi]]))
format_table(read_only(np.array([[1.0, 2.0]])))
print(text.decode().splitlines()[0], len(_write_text.signatures))
"""


def test_csv_writer_compiles_one_version_of_its_number_kernel(tmp_path: Path) -> None:
    # a fresh cache: a kernel loaded from the cache does not show the callees it compiled
    done = subprocess.run(
        [sys.executable, "-c", COMPILE_WRITER],
        env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)),
        capture_output=True,
        text=True,
        check=True,
    )
    assert done.stdout.split() == ["0.1,-2.5e-300", "1"]


LATE_COMPILE_IN_A_FRESH_PROCESS = """
import os, sys, time
from pathlib import Path
from trackplan.cli import warmup
marker = Path(sys.argv[1])
warmup._writer_cached = lambda: False
warmup._compile_late = lambda: marker.write_text(str(os.getpid()))
with warmup.late_compiles():
    deadline = time.monotonic() + 60.0  # a fork can wait long on a loaded machine
    while time.monotonic() < deadline and not (marker.exists() and marker.read_text()):
        time.sleep(0.01)
try:
    os.waitpid(-1, os.WNOHANG)
    reaped = False
except ChildProcessError:
    reaped = True
print(int(marker.read_text()) != os.getpid(), reaped)
"""


@pytest.mark.skipif(not can_fork(), reason="the late-compile process needs fork")
def test_late_compile_process_runs_beside_the_block_and_is_reaped(tmp_path: Path) -> None:
    # in a fresh process, as the CLI forks it: a test worker may hold threads (a Dask or a
    # progress thread of an earlier test), and forking beside threads is not what a run does
    marker = tmp_path / "compiled"
    done = subprocess.run(
        [sys.executable, "-c", LATE_COMPILE_IN_A_FRESH_PROCESS, str(marker)],
        capture_output=True,
        text=True,
        check=True,
    )
    # written by the forked process, which is reaped when the block ends
    assert done.stdout.split() == ["True", "True"]


def test_late_compile_process_is_not_forked_once_the_writer_is_cached(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(warmup, "_writer_cached", lambda: True)
    forked = []
    monkeypatch.setattr(os, "fork", lambda: forked.append(1) or 0)
    with warmup.late_compiles():
        pass
    assert forked == []
