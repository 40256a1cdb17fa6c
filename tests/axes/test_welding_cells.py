"""Issue 29's acceptance: the shipped welding cells, re-checked with our own kinematics.

Each case is planned at its example placement, re-checked by the project's checker, and
then checked again here from the trajectory's joints alone: our own forward kinematics of
the arm and of the positioner (scipy rotations of the chains' published origins and axes,
not the compiled kernels or :class:`~trackplan.robots.machine.Machine`), the tool relative
to the part against the seam as written (its own geometry: a circle, the saddle's sampled
points, a line), and the downhand angles against gravity.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import trackplan
from trackplan.case import Case
from trackplan.planning.result import PlanResult
from trackplan.robots.model import Robot
from trackplan.status import Status

CASES = Path(__file__).parents[2] / "cases"
DOWNHAND = np.radians(10.0)
"""Both bounds of the shipped cases' downhand rule (0.1745 rad), rad."""
ANGLE_SLACK = 1e-6
"""rad: our angles against the rule's bounds (the rule is 0.1745 rad, a hair under 10°)."""


def _transform(xyz: np.ndarray, R: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = xyz
    return T


def _pose(values: np.ndarray) -> np.ndarray:
    """(x, y, z, roll, pitch, yaw) as Trans · Rz(yaw) · Ry(pitch) · Rx(roll), (4, 4)."""
    x, y, z, roll, pitch, yaw = values
    return _transform(
        np.array([x, y, z]), Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_matrix()
    )


def _chain_fk(chain: Robot, q: np.ndarray) -> np.ndarray:
    """Our FK of a revolute chain: origin_i · Rot(axis_i, q_i) in turn, then the tip and the
    tool, shape (N, 4, 4)."""
    T = np.broadcast_to(np.eye(4), (len(q), 4, 4)).copy()
    for i in range(chain.n_dof):
        turn = np.broadcast_to(np.eye(4), (len(q), 4, 4)).copy()
        turn[:, :3, :3] = Rotation.from_rotvec(q[:, i, None] * chain.axes[i]).as_matrix()
        T = T @ chain.origins[i] @ turn
    return T @ chain.T_tip @ chain.T_flange_tool


def _tool_and_part_in_cell(case: Case, q: np.ndarray, X: np.ndarray) -> tuple[np.ndarray, ...]:
    """The tool and the part's definition frame in the cell frame at every sample."""
    n = case.robot.n_dof
    T_cell_base = np.broadcast_to(np.eye(4), (len(q), 4, 4)).copy()
    column = n
    if case.track is not None:
        T_cell_base[:, :3, 3] = q[:, column, None] * case.track.axis
        column += 1
    T_cell_tool = T_cell_base @ _chain_fk(case.robot, q[:, :n])
    T_cell_part = np.broadcast_to(_pose(X), (len(q), 4, 4)).copy()
    if case.positioner is not None:
        chain = case.positioner.chain
        flange = _chain_fk(chain, q[:, column : column + chain.n_dof])
        T_cell_part = _pose(case.positioner.pose) @ flange @ _pose(X)
    return T_cell_tool, T_cell_part


def _planned(name: str) -> tuple[Case, PlanResult]:
    case = trackplan.load_case(CASES / f"{name}.yaml")
    result = trackplan.plan(case, case.bounds.example)
    assert result.success, result.message
    return case, result


def _rechecked(case: Case, result: PlanResult) -> None:
    """The project's checker passes the written joints (a fresh check of q alone)."""
    trajectory = result.trajectory
    report = trackplan.check(
        case, result.placement, trajectory.q, trajectory.sample_time, segment=result.segment
    )
    assert report.success, [v.message for v in report.violations]


def _angles(
    R_cell_part: np.ndarray, normal: np.ndarray, tangent: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Slope of the travel direction and rotation of the normal (part frame, (N, 3)) with
    the part at R_cell_part (N, 3, 3), rad."""
    n_cell = np.einsum("nij,nj->ni", R_cell_part, normal)
    t_cell = np.einsum("nij,nj->ni", R_cell_part, tangent)
    rotation = np.arccos(np.clip(n_cell[:, 2] / np.linalg.norm(n_cell, axis=1), -1, 1))
    slope = np.arcsin(np.clip(np.abs(t_cell[:, 2]) / np.linalg.norm(t_cell, axis=1), 0, 1))
    return slope, rotation


@pytest.mark.slow
def test_pipe_flange_is_welded_downhand_with_the_arm_nearly_still() -> None:
    case, result = _planned("positioner-pipe-flange")
    _rechecked(case, result)
    q = result.trajectory.q
    T_tool, T_part = _tool_and_part_in_cell(case, q, result.placement)
    p = np.einsum("nij,nj->ni", np.linalg.inv(T_part), np.c_[T_tool[:, :3, 3], np.ones(len(q))])
    p = p[:, :3]  # the tool point in the plate's frame: on the circle r = 0.06, z = 0
    radial = np.hypot(p[:, 0], p[:, 1])
    assert np.max(np.hypot(radial - 0.06, p[:, 2])) <= case.task.tolerance
    # the weld normal (the bisector of the plate and the wall) and the travel direction there
    e_r = np.c_[p[:, 0], p[:, 1], np.zeros(len(p))] / radial[:, None]
    normal = e_r + np.array([0.0, 0.0, 1.0])
    tangent = np.cross([0.0, 0.0, 1.0], e_r)
    slope, rotation = _angles(T_part[:, :3, :3], normal, tangent)
    assert slope.max() <= DOWNHAND + ANGLE_SLACK and rotation.max() <= DOWNHAND + ANGLE_SLACK
    arm = np.abs(np.diff(q[:, :6], axis=0)).sum(axis=0)
    turned = np.abs(np.diff(q[:, 7])).sum()  # the positioner's rotate axis
    assert turned > 2 * np.pi - 0.1  # the pipe turns once under the torch …
    assert arm.max() < 0.01 * turned  # … while no arm joint travels a hundredth of that


@pytest.mark.slow
def test_pipe_flange_without_the_positioner_is_refused_naming_the_angle() -> None:
    case = trackplan.load_case(CASES / "positioner-pipe-flange.yaml")
    # the plate where the flange would hold it, but fixed in the cell: the weld normal
    # stays 45° from straight up
    fixed = dataclasses.replace(case, positioner=None)
    X = np.array([1.1, 0.0, 0.53, 0.0, 0.0, np.pi])
    result = trackplan.plan(fixed, X)
    assert result.status is Status.LIMITS_VIOLATED
    assert "downhand" in result.message and "45.0°" in result.message
    assert "no positioner" in result.message


@pytest.mark.slow
def test_pipe_saddle_is_welded_downhand_with_both_axes_moving() -> None:
    case, result = _planned("positioner-pipe-saddle")
    _rechecked(case, result)
    q = result.trajectory.q
    T_tool, T_part = _tool_and_part_in_cell(case, q, result.placement)
    p = np.einsum("nij,nj->ni", np.linalg.inv(T_part), np.c_[T_tool[:, :3, 3], np.ones(len(q))])
    p = p[:, :3]
    # the saddle as sampled (our own densified polyline of saddle.csv) and its normals
    rows = np.loadtxt(CASES / "saddle.csv", delimiter=",", comments="#", skiprows=3)
    points = np.vstack([[0.05, 0.0, 0.0866025403784439], rows[:, :3]])
    normals = np.vstack([rows[-1, 3:], rows[:, 3:]])
    # the distance to every edge of the polyline (a chord of 3.3 mm sags 0.01 mm off the curve)
    a, b = points[:-1], points[1:]
    u = np.clip(
        np.einsum("nki,ki->nk", p[:, None] - a, b - a) / np.einsum("ki,ki->k", b - a, b - a),
        0.0,
        1.0,
    )
    gap = np.linalg.norm(p[:, None] - (a + u[..., None] * (b - a)), axis=2)
    off = gap.min(axis=1)
    nearest = np.argmin(np.linalg.norm(p[:, None, :] - points[None], axis=2), axis=1)
    assert off.max() <= case.task.tolerance
    ahead = np.minimum(nearest + 1, len(points) - 1)
    behind = np.maximum(nearest - 1, 0)
    tangent = points[ahead] - points[behind]  # central difference
    slope, rotation = _angles(T_part[:, :3, :3], normals[nearest], tangent)
    # the sampled normals and our central differences stand a little off the planner's
    # smooth curve: one degree of slack on the 10° rule
    assert slope.max() <= DOWNHAND + np.radians(1.0)
    assert rotation.max() <= DOWNHAND + np.radians(1.0)
    assert result.check.downhand is not None and result.check.downhand.share == 1.0
    tilt, rotate = q[:, 6], q[:, 7]
    assert np.ptp(tilt) > 0.02 and np.ptp(rotate) > np.pi  # both axes move


@pytest.mark.slow
def test_a_3m_seam_on_a_4m_track_is_feasible_and_unreachable_without_it() -> None:
    case, result = _planned("track-long-seam")
    _rechecked(case, result)
    q = result.trajectory.q
    T_tool, T_part = _tool_and_part_in_cell(case, q, result.placement)
    p = np.einsum("nij,nj->ni", np.linalg.inv(T_part), np.c_[T_tool[:, :3, 3], np.ones(len(q))])
    assert np.max(np.hypot(p[:, 1], p[:, 2])) <= case.task.tolerance  # on the line y = z = 0
    assert p[0, 0] == pytest.approx(0.0, abs=case.task.tolerance)
    assert p[-1, 0] == pytest.approx(3.0, abs=case.task.tolerance)
    assert np.ptp(q[:, 6]) > 2.9  # the track carried the arm along the seam
    assert np.all((q[:, 6] >= 0.0) & (q[:, 6] <= 4.0))
    without = trackplan.plan(dataclasses.replace(case, track=None), result.placement)
    assert without.status is Status.UNREACHABLE
    assert "out of reach" in without.message
