"""Controller programs: how long an export takes, and how close the program reads back.

Run with ``python -m benchmarks export``. For each program format and the shipped runs the
round-trip tests use (``tests/programs/test_export_roundtrip.py``: each vendor's built-in
robot and the PUMA560), in both forms (Cartesian; joint, every sample), it plans the case at
its example placement, writes the run folder, and prints:

- the export's wall time (``trackplan.export``: replay, build, print, write; best of
  :data:`REPEATS`, warm) and its ratio against planning the same case (the reference,
  measured in the same run);
- the program's targets, files and bytes;
- the worst read-back error over every target, the files read by the language's test
  parser: TCP position (mm) and orientation (degrees) against the controller-world forward
  kinematics of the planned joints, and joints (rad) against the planned joints. The
  issue's bounds are 0.01 mm, 0.001° and 1e-4° (1.7e-6 rad).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

import trackplan
from tests.programs.roundtrip import expected_targets, frame_difference
from tests.programs.test_export_roundtrip import PARSERS, RUNS
from trackplan.outputs import write_run
from trackplan.robots.kinematics import forward_kinematics
from trackplan.writers import ExportSource

CASES = Path(__file__).resolve().parent.parent / "cases"
REPEATS = 3
"""Exports timed per row; the best is printed."""


def _run_folder(case_name: str, root: Path) -> tuple[Path, float]:
    """The case planned at its example placement and written; the best planning time, s."""
    case = trackplan.load_case(CASES / f"{case_name}.yaml")
    X = np.asarray(case.bounds.example, dtype=float)
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        result = trackplan.plan(case, X)
        times.append(time.perf_counter() - start)
    folder = root / case_name
    write_run(folder, result, case, report=False)
    return folder, min(times)


def _worst_errors(
    format: str, output: Path, source: ExportSource, motion: str
) -> tuple[float, ...]:
    """Targets, files, bytes and the worst position (mm), angle (deg), joint (rad) error."""
    files = {file.name: file.read_bytes().decode("ascii") for file in sorted(output.iterdir())}
    parsed = PARSERS[format](files)
    program = source.program(motion=motion)  # type: ignore[arg-type]
    robot = source.robot
    expected = expected_targets(program)
    world = robot.convention.world_from_base(
        forward_kinematics(robot, np.array([target.model_joints for target in expected]))
    )
    position = angle = joint = 0.0
    for got, want, pose in zip(parsed.targets, expected, world, strict=True):
        if want.pose is not None and got.pose is not None:
            p, a = frame_difference(parsed.base @ got.pose, pose)
            position, angle = max(position, p), max(angle, a)
        if got.joints is not None:
            joint = max(joint, float(np.max(np.abs(np.asarray(got.joints) - want.joints))))
    size = sum(len(text) for text in files.values())
    return len(parsed.targets), len(files), size, position * 1e3, np.degrees(angle), joint


def main() -> None:
    """Print one row per format, case and form."""
    root = Path(tempfile.mkdtemp(prefix="bench-export-"))
    print(
        f"{'format':9}{'case':19}{'form':10}{'export s':>9}{'/ plan':>8}{'targets':>8}"
        f"{'files':>6}{'bytes':>9}{'pos mm':>10}{'deg':>10}{'joint rad':>11}"
    )
    worst = np.zeros(3)
    for format, case_name in RUNS:
        folder, plan_time = _run_folder(case_name, root)
        for motion in ("cartesian", "joint"):
            times = []
            for k in range(REPEATS):
                source = ExportSource.of(folder)
                output = root / f"{case_name}-{format}-{motion}-{k}"
                start = time.perf_counter()
                trackplan.export(source, output, format=format, motion=motion)
                times.append(time.perf_counter() - start)
            figures = _worst_errors(format, output, source, motion)
            worst = np.maximum(worst, figures[3:])
            n, files, size, position, angle, joint = figures
            print(
                f"{format:9}{case_name:19}{motion:10}{min(times):9.2f}{min(times) / plan_time:8.1f}"
                f"{n:8d}{files:6d}{size:9d}{position:10.2e}{angle:10.2e}{joint:11.2e}"
            )
    print(
        f"worst over every row: {worst[0]:.2e} mm (bound 0.01), {worst[1]:.2e} deg "
        f"(bound 0.001), {worst[2]:.2e} rad (bound 1.7e-6)"
    )


if __name__ == "__main__":
    main()
