"""The README: its walk-through runs as written and prints what it shows; it stays short."""

from __future__ import annotations

import re

import numpy as np
import pytest
import yaml

from tests.docs import console
from tests.docs.figures import Workspace

README = console.REPO / "README.md"
CASE = console.REPO / "cases" / "bracket-weld.yaml"


def _walkthrough() -> str:
    text = README.read_text(encoding="utf-8")
    start = text.index("\n## Walk-through")
    return text[start : text.index("\n## ", start + 1)]


def test_readme_is_short():
    assert len(README.read_text(encoding="utf-8").splitlines()) <= 300


def test_walkthrough_shows_the_shipped_case_file():
    shown = re.search(r"```yaml\n(.*?)```", _walkthrough(), re.S)
    assert shown is not None
    assert yaml.safe_load(shown.group(1)) == yaml.safe_load(CASE.read_text(encoding="utf-8"))


def test_walkthrough_commands_are_the_documented_steps():
    commands = console.commands(_walkthrough())
    verbs = [command.argv[1] for command in commands]
    assert verbs == ["validate", "optimize", "plan", "plan", "check", "export"]
    assert all(command.shown for command in commands)


@pytest.mark.slow
def test_walkthrough_runs_as_written(workspace: Workspace):
    """Every command of the walk-through, in order, on the shipped case: exit codes and the
    printed lines (numbers within one unit of the last digit the README prints)."""
    cwd = workspace.root
    for command in console.commands(_walkthrough()):
        done = workspace.run(command.line)
        assert done.returncode == command.exit_code, (command.line, done.stdout, done.stderr)
        problem = console.mismatch(command.shown, done.stdout)
        assert problem is None, f"{command.line}\n{problem}\n--- printed:\n{done.stdout}"
    assert (cwd / "runs" / "bracket" / "report.html").is_file()
    ros = yaml.safe_load((cwd / "runs" / "bracket" / "trajectory.ros.yaml").read_text())
    assert len(ros["points"]) == 9676  # one point per sample, as `check` counted them
    # docs/results.md shows the first two points of this file, to 4 significant digits
    page = (console.REPO / "docs" / "results.md").read_text(encoding="utf-8")
    shown = yaml.safe_load(re.search(r"### The ROS message.*?```yaml\n(.*?)```", page, re.S)[1])
    for want, got in zip(shown["points"][:2], ros["points"][:2], strict=True):
        np.testing.assert_allclose(got["positions"], want["positions"], rtol=0, atol=5e-5)
        for key in ("velocities", "accelerations"):  # 4 significant digits
            np.testing.assert_allclose(got[key], want[key], rtol=5e-4, atol=0, err_msg=key)
        assert got["time_from_start"] == want["time_from_start"]


def test_walkthrough_explains_the_planned_pieces():
    """The lengths the README gives for where the speed dips are those of the planned path."""
    from trackplan import load_case
    from trackplan.paths.path_geometry import PathGeometry

    text = " ".join(_walkthrough().split())
    pieces = PathGeometry.from_case(load_case(CASE)).planned.pieces
    kinds = [piece.kind for piece in pieces]
    starts = np.array([piece.s_start for piece in pieces])
    lengths = np.array([piece.length for piece in pieces])
    # line, blend, arc, blend, line, blend (sharp corner), line, then the sampled curve
    assert kinds[:7] == ["line", "blend", "arc", "blend", "line", "blend", "line"]
    assert f"blend {lengths[1] * 1e3:.0f} mm long" in text
    assert f"last (first) {(0.2 - starts[1]) * 1e3:.1f} mm of the seam" in text
    assert f"s = {starts[1]:.3f}–{starts[4]:.3f} m" in text
    assert f"{lengths[5] * 1e3:.1f} mm blend" in text
    assert f"s = {starts[5]:.3f}–{starts[6]:.3f} m" in text
    curve = [p for p in pieces if p.s_start >= starts[7] - 1e-12]
    short = [p.length for p in curve[:-1] if p.kind == "line"]
    assert len(short) == 3 and 0.1e-3 <= min(short) and max(short) <= 0.3e-3
    blends = [p.length for p in curve if p.kind == "blend"]
    assert all(abs(length - 0.020) < 0.001 for length in blends)
    assert curve[-1].kind == "line"
    assert f"last {curve[-1].length * 1e3:.1f} mm of the curve are straight" in text
