"""Figures the topic pages state are recomputed here, so the pages cannot go stale."""

from __future__ import annotations

import numpy as np
import pytest

from tests.docs import console
from trackplan.paths import (
    LineSpec,
    NominalPath,
    build_path,
    corrected_corner_radius,
    paper_corner_angle,
    paper_corner_radius,
)


def _text(page: str) -> str:
    return " ".join((console.REPO / "docs" / page).read_text(encoding="utf-8").split())


def test_paths_page_paper_corner_table():
    """docs/paths.md, "The paper's corner"."""
    text = _text("paths.md")
    a, b, c = np.zeros(3), np.array([0.5, 0.0, 0.0]), np.array([0.3, 0.0, 0.5])
    rho = 1e-3
    beta = paper_corner_angle(a, b, c)
    assert f"β = {np.degrees(beta):.3f}°" in text
    assert f"turns by {180 - np.degrees(beta):.3f}°" in text
    r_paper, r_fixed = paper_corner_radius(beta, rho), corrected_corner_radius(beta, rho)
    assert f"r = {r_paper * 1e3:.3f} mm" in text and f"r = {r_fixed * 1e3:.3f} mm" in text
    assert f"{1 / r_paper:.1f} 1/m" in text and f"{1 / r_fixed:.1f} 1/m" in text
    nominal = NominalPath.from_specs(a, (LineSpec(b), LineSpec(c)))
    planned = build_path(nominal, rho)
    blend = next(piece for piece in planned.pieces if piece.kind == "blend")
    s = np.linspace(blend.s_start, blend.s_start + blend.length, 20001)
    peak = np.linalg.norm(planned.sample(s).curvature, axis=1).max()
    assert f"blend {blend.length * 1e3:.3f} mm" in text
    assert f"**{peak:.1f} 1/m**" in text
    assert f"{planned.length:.5f} m long (nominal {nominal.length:.5f} m)" in text
    arc = next(p for p in build_path(nominal, rho, mode="paper").pieces if p.kind == "arc")
    assert f"arc {arc.length * 1e3:.3f} mm" in text


def _zones(case_name: str, normal: tuple[float, float, float] | None = None) -> np.ndarray:
    from trackplan import load_case
    from trackplan.paths.path_geometry import PathGeometry
    from trackplan.planning.tool_zones import transition_zones
    from trackplan.tool import ToolFrame, ToolSpec

    case = load_case(console.REPO / "cases" / f"{case_name}.yaml")
    spec = case.task.tool
    if normal is not None:
        spec = ToolSpec(frame=ToolFrame.SEAM, normal=np.array(normal))
    return transition_zones(spec, PathGeometry.from_case(case), case.task.tolerance)


def test_tool_page_transition_zones():
    """docs/tool.md: the transition zones of its examples (geometry only, no search)."""
    text = _text("tool.md")
    ((s0, s1, bound),) = _zones("seam-weld-fixed")
    assert f"nominal s from {s0:.3f} to {s1:.3f} m), bound {bound:.3f} rad" in text
    assert f"({np.degrees(bound):.1f}°)" in text
    ((s0, s1, bound),) = _zones("paper-corner", (0.0, 1.0, 0.3))
    assert (
        f"has one zone of {(s1 - s0) * 1e3:.0f} mm around the corner, bound {bound:.2f} rad" in text
    )
    assert len(_zones("paper-corner", (0.0, 1.0, 0.0))) == 0
    ((s0, s1, bound),) = _zones("bracket-two-faces")
    assert f"from nominal s = {s0:.3f} to {s1:.3f} m with bound {bound:.2f} rad" in text


def test_tool_page_two_faces_blend():
    """docs/tool.md: the blend of the two-faces bracket and the window around it."""
    from trackplan import load_case
    from trackplan.paths.path_geometry import PathGeometry

    text = _text("tool.md")
    pieces = PathGeometry.from_case(load_case(console.REPO / "cases/bracket-two-faces.yaml"))
    (blend,) = [piece for piece in pieces.planned.pieces if piece.kind == "blend"]
    assert f"the blend piece ({blend.length * 1e3:.0f} mm) widened by 5 mm" in text
    assert f"a {blend.length * 1e3 + 10:.0f} mm window" in text


@pytest.mark.slow
def test_dynamics_page_torque_limit_example():
    """docs/dynamics.md: joint 1 of the PUMA560 limited to 35 N·m (and 30 N·m) on the corner
    case at the paper's placement (as tests/timing/test_torque_limits.py plans it)."""
    import dataclasses

    from trackplan import load_case
    from trackplan.planning.plan import plan

    text = _text("dynamics.md")
    case = load_case(console.REPO / "cases" / "paper-corner.yaml")
    X = case.bounds.example
    base = plan(case, X)

    def limited(newton_metres: float):
        torque_max = np.array(case.robot.dynamics.torque_max)
        torque_max[0] = newton_metres
        dynamics = dataclasses.replace(case.robot.dynamics, torque_max=torque_max)
        robot = dataclasses.replace(case.robot, dynamics=dynamics)
        return plan(dataclasses.replace(case, robot=robot), X)

    at_35, at_30 = limited(35.0), limited(30.0)
    assert at_35.success and at_30.success
    used = (1 - at_35.check.joint_margins["torque"][0]) * 100
    assert (
        f"takes {at_35.duration:.2f} s instead of {base.duration:.2f} s and is feasible, "
        f"joint 1 at {used:.1f} % of its torque limit; at 30 N·m it takes "
        f"{at_30.duration:.1f} s."
    ) in text


@pytest.mark.slow
def test_cell_page_least_self_distances():
    """docs/cell.md: the least distance between non-adjacent links along the plans of the
    shipped cases at the placements tests/cell/test_robot_bodies.py plans them at."""
    from tests.cell.test_robot_bodies import SHIPPED_PLANS, TS
    from trackplan import load_case
    from trackplan.cell.check import check_cell
    from trackplan.cell.model import Cell
    from trackplan.cell.screening import CellGeometry
    from trackplan.planning.plan import plan

    text = _text("cell.md")
    for name, placement in SHIPPED_PLANS.items():
        case = load_case(console.REPO / "cases" / f"{name}.yaml")
        planned = plan(case, np.array(placement))
        geometry = CellGeometry.from_cell(Cell(), case.robot)
        report = check_cell(geometry, case.robot, planned.trajectory.q, TS, np.eye(4))
        assert f"{name} {report.min_clearance * 1e3:.1f} mm" in text, name
