"""The joint path of one placed path: poses and IK on the planning grid, computed once.

A plan turns the placed path into joints once: :meth:`JointPath.solve` evaluates the tool
poses at every point of the planning grid (and of the small stencils around them that give
the derivatives in s), solves the path IK on one continuous branch in one batched call, and
keeps q(s), dq/ds, d²q/ds² and d³q/ds³ there. Every time law, the reference laws and the
search's final plan read it; only the trajectory samples themselves need the IK again
(:meth:`JointPath.q`), so that the written joints are exact IK solutions of the path.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from trackplan.axes.profile import AxesProfile
from trackplan.derived import derived
from trackplan.frames import placement_transform, tool_pose_parts, tool_poses
from trackplan.paths.path_geometry import PathGeometry
from trackplan.profiles import Profile
from trackplan.robots.families import ik_family
from trackplan.robots.machine import Machine, arm_of
from trackplan.robots.model import Robot
from trackplan.robots.path_ik import PathIK, branch_joints_along, solve_path_ik
from trackplan.status import Status
from trackplan.stencils import stencil_derivatives, stencil_points
from trackplan.tool import ToolFrame, ToolOrientation
from trackplan.tool.weave import WeaveTrack, weave_offsets

STENCIL_FRACTION = 0.1
"""Stencil spacing as a share of the grid step: small against the scale on which the
derivatives change, large against the IK's round-off."""


@dataclass(frozen=True, eq=False)
class JointPath:
    """IK of a placed path on its planning grid, one branch, continuous.

    With a :class:`~trackplan.robots.machine.Machine` (a track, a positioner) the joints are
    the machine's joint vector: the arm's by IK, the external axes' from :attr:`axes`, and
    the placement X places the part in the machine's carrier frame.

    Attributes
    ----------
    robot
        The robot, or the machine of the robot and its external axes.
    geometry
        The case's paths and zones.
    placement
        X = (x, y, z, roll, pitch, yaw), shape (6,), metres and radians.
    tool
        Tool orientation along the path (spec and chosen spin).
    s
        Planning grid, shape (G,), m, non-decreasing; a zone boundary appears once per
        zone it bounds (the derivatives there are one-sided, from inside each zone).
    zone
        Index of each grid point's zone in ``geometry.zones()``, shape (G,), int.
    q
        Joint positions at the grid, shape (G, n), rad: continuous, inside the limits.
    dq, ddq, dddq
        dq/ds, d²q/ds², d³q/ds³ at the grid, shape (G, n), rad/m, rad/m², rad/m³.
    ik
        The path IK over the grid and its stencils (branch, status, message, margin).
    axes
        The external axes along the path (a machine's), or None for a robot.
    redundancy
        A redundant arm's free parameter along the path (:attr:`IKFamily.redundancy`:
        the arm angle, or a joint), rad over s ∈ [0, length]; None for other arms.
    """

    robot: Robot | Machine
    geometry: PathGeometry
    placement: np.ndarray
    tool: ToolOrientation
    s: np.ndarray
    zone: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    dddq: np.ndarray
    ik: PathIK
    axes: AxesProfile | None = None
    redundancy: Profile | None = None

    @classmethod
    def solve(
        cls,
        robot: Robot | Machine,
        geometry: PathGeometry,
        placement: np.ndarray,
        tool: ToolOrientation,
        branch: int | None = None,
        axes: AxesProfile | None = None,
        redundancy: Profile | None = None,
    ) -> JointPath:
        """Poses and path IK of the planning grid, in one pose pass and one IK pass.

        Parameters
        ----------
        robot
            The robot, or a machine (then ``axes`` is required).
        geometry
            The case's paths (:meth:`PathGeometry.zone_grids` gives the grid).
        placement
            X, shape (6,), metres and radians.
        tool
            Tool orientation along the path (:class:`trackplan.tool.ToolOrientation`).
        branch
            Force an IK branch; default: the usable one with the largest margin.
        axes
            A machine's external axes along the path (track, positioner), m and rad.
        redundancy
            A redundant arm's free parameter along the path, rad (required for one:
            :func:`trackplan.redundancy.choose_redundancy` chooses it).

        Returns
        -------
        JointPath
            Check :attr:`success` before using the joints: an unreachable pose, a branch
            switch or a joint range left shows in :attr:`status` and :attr:`message`.
        """
        placement = np.asarray(placement, dtype=float)
        grid = _planning_grid(geometry)
        arm = arm_of(robot)
        rotations = _rotations(tool, grid.points.ravel(), grid.tangents)
        positions = _woven(
            geometry, tool, grid.points.ravel(), grid.positions, grid.tangents, rotations
        )
        poses = tool_poses(placement, positions, rotations)
        external = _external(robot, axes, grid.points.ravel())
        if external is not None:
            poses = _machine(robot).base_carrier_at(external) @ poses
        free = _free(arm, redundancy, grid.points.ravel())
        ik = solve_path_ik(
            arm, poses[None], branch=branch, free=None if free is None else free[None]
        )
        q_points = ik.q[0].reshape(*grid.points.shape, arm.n_dof)
        if external is not None:
            q_points = np.concatenate([q_points, external.reshape(*grid.points.shape, -1)], axis=-1)
        dq, ddq, dddq = stencil_derivatives(q_points, grid.offset, grid.h)
        q = q_points[np.arange(len(grid.s)), grid.offset]
        return cls(
            robot,
            geometry,
            placement,
            tool,
            grid.s,
            grid.zone,
            q,
            dq,
            ddq,
            dddq,
            ik,
            axes,
            redundancy,
        )

    @property
    def arm(self) -> Robot:
        """The robot arm (the robot itself, or a machine's arm)."""
        return arm_of(self.robot)

    @property
    def success(self) -> bool:
        """True when every grid pose is reached on one branch, inside the joint range."""
        return bool(self.ik.success[0])

    @property
    def status(self) -> Status:
        """:attr:`Status.FEASIBLE`, or why the path has no joint path."""
        return self.ik.status[0]

    @property
    def message(self) -> str:
        """One line: the branch and its margin, or what is wrong and where."""
        return self.ik.message[0]

    @property
    def branch(self) -> int:
        """The IK branch (a closed-form label, or the first-pose solution a tracked family
        follows)."""
        return int(self.ik.branch[0])

    @property
    def length(self) -> float:
        """Length of the planned path, m."""
        return float(self.geometry.planned.length)

    @property
    def T_base_part(self) -> np.ndarray:
        """The placement transform T_X, shape (4, 4)."""
        return placement_transform(self.placement)

    def R_part_tool(self, s: np.ndarray) -> np.ndarray:
        """Tool orientation in the definition frame at arc lengths ``s`` (M,), shape (M, 3, 3)."""
        s_path, _, tangent = self.geometry.planned.points(np.asarray(s, dtype=float))
        return self.tool.rotations(s_path, tangent)

    def poses(self, s: np.ndarray) -> np.ndarray:
        """Tool poses in the arm's base frame at arc lengths ``s`` (M,), shape (M, 4, 4)."""
        return placed_tool_poses(self.robot, self.geometry, self.placement, self.tool, self.axes, s)

    def joints(self, s: np.ndarray) -> np.ndarray:
        """Joint positions at arc lengths ``s`` by IK on this path's branch.

        Each joint is put on the winding of the grid solution nearest in s, so the result
        continues :attr:`q` whatever the order of ``s``. The IK reads the poses' rotations
        and positions (:func:`trackplan.frames.tool_pose_parts`), the values of
        :meth:`poses`, without building them.

        Parameters
        ----------
        s
            Arc lengths on the planned path, shape (M,), m.

        Returns
        -------
        numpy.ndarray
            Shape (M, n), rad.
        """
        s = np.asarray(s, dtype=float)
        s_path, position, tangent = self.geometry.planned.points(s)
        rotations = _rotations(self.tool, s_path, tangent)
        position = _woven(self.geometry, self.tool, s_path, position, tangent, rotations)
        R_base_tool, p_base_tool = tool_pose_parts(self.placement, position, rotations)
        grid, q_grid = self._distinct_grid
        external = _external(self.robot, self.axes, s)
        free = _free(self.arm, self.redundancy, s)
        if external is None:
            return branch_joints_along(
                self.arm, R_base_tool, p_base_tool, self.branch, s, grid, q_grid, free=free
            )
        carrier = _machine(self.robot).base_carrier_at(external)
        R_base_tool = carrier[:, :3, :3] @ R_base_tool
        p_base_tool = np.einsum("mij,mj->mi", carrier[:, :3, :3], p_base_tool) + carrier[:, :3, 3]
        n_arm = self.arm.n_dof
        q_arm = branch_joints_along(
            self.arm,
            np.ascontiguousarray(R_base_tool),
            np.ascontiguousarray(p_base_tool),
            self.branch,
            s,
            grid,
            np.ascontiguousarray(q_grid[:, :n_arm]),
            free=free,
        )
        return np.concatenate([q_arm, external], axis=1)

    def interpolate(self, s: np.ndarray) -> np.ndarray:
        """q at ``s`` (M,) by linear interpolation of the grid, shape (M, n), rad."""
        grid, q_grid = self._distinct_grid
        s = np.asarray(s, dtype=float)
        out = np.empty((len(s), q_grid.shape[1]))
        for j in range(q_grid.shape[1]):
            out[:, j] = np.interp(s, grid, q_grid[:, j])
        return out

    @cached_property
    def _distinct_grid(self) -> tuple[np.ndarray, np.ndarray]:
        """The grid with each zone boundary once, shape (G',), m, and q there, shape
        (G', n), rad."""
        grid, first = np.unique(self.s, return_index=True)
        return grid, np.ascontiguousarray(self.q[first])

    def derivatives(
        self, s: np.ndarray, lo: np.ndarray, hi: np.ndarray, h: np.ndarray | float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """dq/ds, d²q/ds², d³q/ds³ at any arc lengths, by IK on stencils kept in [lo, hi].

        Parameters
        ----------
        s
            Arc lengths, shape (M,), m.
        lo, hi
            Interval each stencil stays in (a zone), shape (M,) or scalars, m.
        h
            Stencil spacing, m (``hi - lo ≥ 4 h``).

        Returns
        -------
        tuple of numpy.ndarray
            Each shape (M, n), rad/m, rad/m², rad/m³.
        """
        spacing = np.asarray(h, dtype=float)
        points, offset = stencil_points(np.asarray(s, dtype=float), lo, hi, spacing)
        q = self.joints(points.ravel()).reshape(*points.shape, self.robot.n_dof)
        return stencil_derivatives(q, offset, spacing)


def _external(robot: Robot | Machine, axes: AxesProfile | None, s: np.ndarray) -> np.ndarray | None:
    """A machine's external axes at arc lengths ``s`` (M,), shape (M, n_external), or None
    for a robot.

    Raises
    ------
    ValueError
        When a machine comes without its axes' profile, or with one of another size.
    """
    if not isinstance(robot, Machine):
        return None
    if axes is None or axes.n_axes != robot.n_external:
        found = None if axes is None else axes.n_axes
        raise ValueError(
            f"a machine with {robot.n_external} external axes needs their profile, got {found}"
        )
    return axes.values(s)


def placed_tool_poses(
    robot: Robot | Machine,
    geometry: PathGeometry,
    placement: np.ndarray,
    tool: ToolOrientation,
    axes: AxesProfile | None,
    s: np.ndarray,
) -> np.ndarray:
    """Tool poses of a placed path in the arm's base frame at arc lengths ``s`` (M,).

    The weave is added and, for a machine, the part is carried by the external axes
    ``axes`` (required then).

    Returns
    -------
    numpy.ndarray
        Shape (M, 4, 4), m.
    """
    s = np.asarray(s, dtype=float)
    s_path, position, tangent = geometry.planned.points(s)
    rotations = _rotations(tool, s_path, tangent)
    position = _woven(geometry, tool, s_path, position, tangent, rotations)
    poses = tool_poses(np.asarray(placement, dtype=float), position, rotations)
    external = _external(robot, axes, s)
    if external is None:
        return poses
    carried: np.ndarray = _machine(robot).base_carrier_at(external) @ poses
    return carried


def _free(arm: Robot, redundancy: Profile | None, s: np.ndarray) -> np.ndarray | None:
    """A redundant arm's free parameter at arc lengths ``s`` (M,), shape (M,), rad; None for
    other arms.

    Raises
    ------
    ValueError
        When a redundant arm comes without its profile.
    """
    parameter = ik_family(arm).redundancy
    if parameter is None:
        return None
    if redundancy is None:
        raise ValueError(f"{arm.name} is redundant: its {parameter.name} profile is required")
    return redundancy.value(s)


def _machine(robot: Robot | Machine) -> Machine:
    """The machine of a joint path that has external axes."""
    assert isinstance(robot, Machine)
    return robot


def _rotations(tool: ToolOrientation, s: np.ndarray, tangent: np.ndarray) -> np.ndarray:
    """``R_part_tool`` at arc lengths ``s`` (M,) with planned tangents (M, 3): shape
    (M, 3, 3), or one (3, 3) where the tool holds one orientation along the whole path
    (part frame, constant spin): the rotation every row would repeat, computed once per
    spec and spin value (it depends on nothing else)."""
    if tool.spec.frame is ToolFrame.PART and len(tool.spin.coefficients) == 1 and len(s):
        spin = float(tool.spin.coefficients[0])

        def held() -> np.ndarray:
            rotation = tool.rotations(s[:1], tangent[:1])[0]
            rotation.flags.writeable = False
            return rotation

        # the one rotation of the held tool, kept on its spec (read-only)
        return derived(tool.spec, ("held rotation", spin), held)
    return tool.rotations(s, tangent)


def _woven(
    geometry: PathGeometry,
    tool: ToolOrientation,
    s: np.ndarray,
    position: np.ndarray,
    tangent: np.ndarray,
    rotations: np.ndarray,
) -> np.ndarray:
    """The tool points at arc lengths ``s`` (M,): the planned path's ``position`` (M, 3)
    plus the geometry's weave across it (:func:`trackplan.tool.weave.weave_offsets`), m."""
    weave = geometry.weave
    if not isinstance(weave, WeaveTrack):
        return position
    return position + weave_offsets(weave, tool, s, tangent, rotations)


@dataclass(frozen=True, eq=False)
class _PlanningGrid:
    """The planning grid of a path geometry and its stencils: the same for every placement.

    Attributes
    ----------
    s, zone
        Grid arc lengths (G,), m, and the zone of each, (G,).
    points, offset
        Stencil arc lengths (G, W), m, and the column of each grid point in them, (G,).
    h
        Stencil spacing of each grid point, (G,), m.
    positions, tangents
        Planned-path points and unit tangents at the stencils, shape (G·W, 3), m and
        unitless, definition frame.
    """

    s: np.ndarray
    zone: np.ndarray
    points: np.ndarray
    offset: np.ndarray
    h: np.ndarray
    positions: np.ndarray
    tangents: np.ndarray


def _planning_grid(geometry: PathGeometry) -> _PlanningGrid:
    """The geometry's planning grid (:meth:`PathGeometry.zone_grids`), built once per geometry."""
    return derived(geometry, "planning grid", lambda: _build_grid(geometry))


def _build_grid(geometry: PathGeometry) -> _PlanningGrid:
    """The planning grid of a geometry, its arrays read-only."""
    grids = geometry.zone_grids()
    zones = geometry.zones()
    s = np.concatenate(grids)
    zone = np.repeat(np.arange(len(grids)), [len(g) for g in grids])
    lo = np.array([z[0] for z in zones])[zone]
    hi = np.array([z[1] for z in zones])[zone]
    steps = np.array([(g[-1] - g[0]) / max(len(g) - 1, 1) for g in grids])
    h = STENCIL_FRACTION * steps[zone]
    points, offset = stencil_points(s, lo, hi, h)
    sample = geometry.planned.sample(points.ravel())
    positions, tangents = sample.position, sample.tangent
    for array in (s, zone, points, offset, h, positions, tangents):
        array.flags.writeable = False
    return _PlanningGrid(s, zone, points, offset, h, positions, tangents)
