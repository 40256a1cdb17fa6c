"""The paper's trajectory (Section 3.1) as written, for reproduction.

The planned path of the paper mode is made of lines and circular arcs (Eq. 10's tangent
arcs at line–line corners, and the user's arcs). Each piece is turned into samples at Ts:

- **Arcs** (Eq. 11–12): constant tangential speed. With ``N = ⌈L / (v_t^max Ts)⌉`` the arc
  is cut into N equal pieces, so the speed is ``L / (N Ts) ≤ v_t^max``. The poses go to the
  joints by resolved-rate IK (Eq. 19–27, with the compensation step).
- **Lines** (Eq. 13–18): via points equally spaced along the line, mapped to the joints by
  closed-form IK on the chosen branch. The paper leaves the spacing open; too fine a spacing
  stalls the forward piece below v_r (each interval is rounded up to whole periods, which
  cancels any acceleration saving less than Ts: with 1 mm at Ts = 1 ms the paper's corner
  stalls near 0.11 m/s), so it is chosen per line by :meth:`_PaperPlanner.via_spacing`.

  *Forward piece* from P1 (at rest at the start of the path or at a stop; at the adjoining
  arc's speed after an arc, the joint velocity being ``J⁻¹ [v t; 0]``): for each via
  interval, every joint's minimum time at its maximum acceleration given its current
  velocity (Eq. 13 with q̈max, not q̇max, under the root:
  ``t_i = (−w + √(w² + 2 q̈max |Δq_i|)) / q̈max`` with ``w = sign(Δq_i) q̇_i``), the largest
  over the joints (Eq. 14), rounded up to a whole number of periods τ; the constant
  accelerations ``q̈_i = 2 (Δq_i − q̇_i τ) / τ²`` (Eq. 15), integrated at Ts (Eq. 16–17).
  Inequality (5) is kept as the paper asks: when the tool speed at the end of an interval
  would exceed v_r, τ is lengthened (whole periods) until it does not. The forward piece
  ends at the first via point where the speed bound sets τ (P_F: the speed has reached
  v_r to within one period's rounding).

  *Reverse piece*: the same from P2 backwards (at rest, or at the next arc's speed), then
  played in reverse time.

  *Middle piece* (Eq. 18) from P_F to P_R at the rated speed in Cartesian space: the
  paper's step ``v_r Ts`` does not divide the length, so, as for the arcs, the piece is cut
  into ``N = ⌈L / (v_r Ts)⌉`` equal steps (speed ≤ v_r), mapped by resolved-rate IK.

  A line too short to reach v_r has no middle piece: the forward and reverse pieces meet at
  the first via point where the forward speed reaches the reverse speed.

Pieces are merged in order into one sequence at Ts (3.1.3). Where a piece planned in joint
space starts, its exact IK configuration replaces the last resolved-rate sample of the
piece before (the same pose), so resolved-rate drift does not carry over.

Line–line junctions without an arc between them (collinear lines, stops) are passed at rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.choices import Timing
from trackplan.errors import CaseError
from trackplan.frames import placement_transform
from trackplan.jointpath import JointPath
from trackplan.paths.curves import unwrap_closed_arc
from trackplan.robots.kinematics import forward_kinematics, jacobian
from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot
from trackplan.robots.path_ik import solve_path_ik
from trackplan.robots.resolved_rate import solve_path_resolved_rate
from trackplan.status import Status
from trackplan.task import Task
from trackplan.timing.protocol import TimedPath, TimeLaw, unsampled

MIN_VIA_SPACING = 1e-3
"""Smallest distance between the via points of a line, m."""
SAVING_PERIODS = 4.0
"""Periods each via interval must be able to save by accelerating at v_r (see the module
docstring: a finer spacing stalls the forward piece below v_r)."""
SPEED_REACHED = 1e-6
"""Relative shortfall of v_r at which the forward piece counts as having reached it."""


class _PlanStop(Exception):
    """A piece could not be mapped to the joints (carries the status and message)."""

    def __init__(self, status: Status, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.message = message


@dataclass(frozen=True, eq=False)
class _Ramp:
    """Joint-space constant-acceleration motion over via points (Eq. 13–17).

    Attributes
    ----------
    samples
        Joint positions at Ts from via 0 (included), shape (K, n), rad.
    via_sample
        Sample index at which each via point reached is passed, shape (V,).
    via_speed
        Tool speed at each via point reached, shape (V,), m/s.
    reached
        Index of the via point where v_r was reached, or None.
    """

    samples: np.ndarray
    via_sample: np.ndarray
    via_speed: np.ndarray
    reached: int | None


def plan_paper_trajectory(joint_path: JointPath, task: Task) -> TimedPath:
    """Sample the paper's trajectory (Section 3.1) along a placed path.

    Parameters
    ----------
    joint_path
        The placed path's joint path on the chosen branch; its geometry must be built
        with ``mode="paper"`` (lines and Eq. 10 tangent arcs).
    task
        Speeds (m/s), Ts (s) and the tool orientation.

    Returns
    -------
    TimedPath
        The samples, or none with the reason (resolved-rate divergence, a via point
        off the branch).
    """
    robot = joint_path.robot
    if isinstance(robot, Machine):
        raise CaseError(
            "the paper's time law drives the arm alone: a case with a track or a positioner "
            "needs timing: smooth",
            key="task.timing",
        )
    planner = _PaperPlanner(robot, task, joint_path)
    try:
        q, s = planner.run(joint_path.q[0])
    except _PlanStop as stop:
        return unsampled(Timing.PAPER, stop.status, stop.message, task.sample_time, robot.n_dof)
    return TimedPath(
        timing=Timing.PAPER,
        success=True,
        status=Status.FEASIBLE,
        message="",
        sample_time=task.sample_time,
        s=s,
        q=q,
    )


class _PaperPlanner:
    """Walks the pieces of the planned path and appends their samples."""

    def __init__(self, robot: Robot, task: Task, joint_path: JointPath) -> None:
        self.robot = robot
        self.task = task
        self.joint_path = joint_path
        self.path = joint_path.geometry.planned
        X = joint_path.placement
        self.X = X
        self.branch = joint_path.branch
        self.Ts = task.sample_time
        self.T_base_part = placement_transform(X)
        self.pieces = tuple(self.path.pieces)
        stops = np.asarray(list(self.path.stops), dtype=float)
        self.rest_at = [
            bool(np.any(np.abs(stops - piece.s_start) <= 1e-9)) for piece in self.pieces
        ]  # speed zero at the start of piece k

    # -- speeds --------------------------------------------------------------------------

    def _arc_speed(self, k: int) -> float:
        """Eq. 11–12: constant speed making the piece a whole number of periods, m/s."""
        return self.pieces[k].length / (self._arc_steps(k) * self.Ts)

    def _arc_steps(self, k: int) -> int:
        length = self.pieces[k].length
        return max(1, int(np.ceil(length / (self.task.corner_speed * self.Ts) - 1e-9)))

    def _junction_speed(self, k: int) -> float:
        """Tool speed at the start of piece k (the end of piece k - 1), m/s."""
        if k == 0 or k >= len(self.pieces) or self.rest_at[k]:
            return 0.0
        if not self.pieces[k - 1].straight:
            return self._arc_speed(k - 1)
        if not self.pieces[k].straight:
            return self._arc_speed(k)
        return 0.0

    # -- the walk ------------------------------------------------------------------------

    def run(self, q_start: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All samples (N, n) and their arc lengths (N,)."""
        samples = [np.asarray(q_start, dtype=float)[None]]
        owner = [np.array([0])]
        for k, piece in enumerate(self.pieces):
            if piece.straight:
                q_new = self._line(k, samples[-1][-1])
                # the line starts with its exact IK configuration of the junction pose
                samples[-1] = np.concatenate([samples[-1][:-1], q_new[:1]])
                samples.append(q_new[1:])
            else:
                q_new = self._arc(k, samples[-1][-1])
                samples.append(q_new[1:])
            owner.append(np.full(len(samples[-1]), k))
        q = np.concatenate(samples)
        if not np.all(np.isfinite(q)):
            raise _PlanStop(Status.UNREACHABLE, "resolved-rate IK diverged (singularity)")
        return q, self._arc_lengths(q, np.concatenate(owner))

    def _resolved_rate(self, s: np.ndarray, q0: np.ndarray) -> np.ndarray:
        """Eq. 19–27 from q0 through the poses at arc lengths ``s`` (M,); row 0 is q0."""
        poses = self.joint_path.poses(np.clip(s, 0.0, self.path.length))
        q = np.asarray(solve_path_resolved_rate(self.robot, poses, q0))
        q = q.copy()
        q[0] = q0
        return q

    def _arc(self, k: int, q0: np.ndarray) -> np.ndarray:
        """Constant-speed arc (Eq. 11–12) by resolved-rate IK, shape (N + 1, n)."""
        piece = self.pieces[k]
        steps = self._arc_steps(k)
        s = piece.s_start + np.linspace(0.0, piece.length, steps + 1)
        s[-1] = min(s[-1], self.path.length)
        return self._resolved_rate(s, q0)

    def _line(self, k: int, q_near: np.ndarray) -> np.ndarray:
        """Forward, middle and reverse pieces of line k (Eq. 13–18), from P1 to P2."""
        piece = self.pieces[k]
        fine = self._via_points(piece, MIN_VIA_SPACING, q_near)[1]
        spacing = self.via_spacing(fine, piece.length / (len(fine) - 1))
        sample, q_via = self._via_points(piece, spacing, q_near)
        direction = self.T_base_part[:3, :3] @ sample.tangent[0]
        v_start = self._junction_speed(k)
        v_end = self._junction_speed(k + 1)
        rated = self.task.rated_speed
        forward = self._ramp(q_via, self._joint_velocity(q_via[0], v_start * direction), rated)
        backward = self._ramp(
            q_via[::-1], self._joint_velocity(q_via[-1], -v_end * direction), rated
        )
        last = len(q_via) - 1
        j_forward = forward.reached if forward.reached is not None else last
        j_reverse = last - (backward.reached if backward.reached is not None else last)
        if j_forward < j_reverse and forward.reached is not None and backward.reached is not None:
            head = forward.samples[: forward.via_sample[j_forward] + 1]
            tail = backward.samples[: backward.via_sample[last - j_reverse] + 1][::-1]
            middle = self._middle(sample.s[j_forward], sample.s[j_reverse], head[-1])
            return np.concatenate([head, middle[1:-1], tail])
        j_meet = self._meeting_via(forward, backward, last)
        head = forward.samples[: forward.via_sample[j_meet] + 1]
        tail = backward.samples[: backward.via_sample[last - j_meet] + 1][::-1]
        return np.concatenate([head, tail[1:]])

    def _via_points(self, piece, spacing: float, q_near: np.ndarray):  # type: ignore[no-untyped-def]
        """Equally spaced via points at least ``spacing`` apart (path sample, q (V, n))."""
        n_steps = max(1, int(np.floor(piece.length / spacing + 1e-9)))
        s_via = piece.s_start + np.linspace(0.0, piece.length, n_steps + 1)
        s_via[-1] = min(s_via[-1], self.path.length)
        sample = self.path.sample(s_via)
        return sample, self._via_ik(sample.s, q_near)

    def via_spacing(self, q_fine: np.ndarray, step: float) -> float:
        """Via spacing h of a line whose joint path is sampled every ``step`` m, m.

        Accelerating over one interval at tool speed v saves a joint about
        ``q̈max h² / (2 k v³)`` of the constant-speed time (k = |dq/ds|, rad/m). Rounding
        up to whole periods (Eq. 14) cancels any saving below Ts: the ramp then stalls at a
        speed h / (m Ts). h is chosen so that every joint saves at least
        :data:`SAVING_PERIODS` periods at v_r, and at least :data:`MIN_VIA_SPACING`.
        """
        slope = np.max(np.abs(np.diff(q_fine, axis=0)), axis=0) / step  # k_i, rad/m
        worst = float(np.max(slope / self.robot.a_max))
        v = self.task.rated_speed
        return max(MIN_VIA_SPACING, float(np.sqrt(2.0 * SAVING_PERIODS * self.Ts * v**3 * worst)))

    @staticmethod
    def _meeting_via(forward: _Ramp, backward: _Ramp, last: int) -> int:
        """First via point where the forward speed reaches the reverse speed."""
        n_forward = len(forward.via_speed)
        reverse_speed = backward.via_speed[::-1]  # index j ↔ via last - (len - 1 - j)
        first_reverse = last - (len(backward.via_speed) - 1)
        for j in range(max(first_reverse, 0), min(n_forward - 1, last) + 1):
            if forward.via_speed[j] >= reverse_speed[j - first_reverse]:
                return j
        return min(n_forward - 1, last) if n_forward - 1 >= first_reverse else first_reverse

    def _middle(self, s_from: float, s_to: float, q0: np.ndarray) -> np.ndarray:
        """Eq. 18 at (at most) v_r in equal steps, by resolved-rate IK, shape (N + 1, n)."""
        length = float(s_to - s_from)
        steps = max(1, int(np.ceil(length / (self.task.rated_speed * self.Ts) - 1e-9)))
        return self._resolved_rate(np.linspace(s_from, s_to, steps + 1), q0)

    def _via_ik(self, s: np.ndarray, q_near: np.ndarray) -> np.ndarray:
        """Closed-form IK of the via poses at arc lengths ``s`` on the branch, continuous
        with ``q_near``."""
        poses = self.joint_path.poses(s)
        result = solve_path_ik(self.robot, poses[None], branch=self.branch)
        if not result.success[0]:
            raise _PlanStop(result.status[0], str(result.message[0]))
        q: np.ndarray = result.q[0]
        near: np.ndarray = q - 2 * np.pi * np.round((q[0] - q_near) / (2 * np.pi))
        return near

    def _joint_velocity(self, q: np.ndarray, velocity: np.ndarray) -> np.ndarray:
        """q̇ giving the tool the linear velocity ``velocity`` (3,) and no rotation (Eq. 20)."""
        if not np.any(velocity):
            return np.zeros(self.robot.n_dof)
        twist = np.concatenate([velocity, np.zeros(3)])
        qd: np.ndarray = np.linalg.lstsq(jacobian(self.robot, q), twist, rcond=None)[0]
        return qd

    def _ramp(self, q_via: np.ndarray, qd0: np.ndarray, rated: float) -> _Ramp:
        """Eq. 13–17 over the via points until the tool reaches ``rated`` (m/s)."""
        robot, Ts = self.robot, self.Ts
        a_max = robot.a_max
        qd = qd0.copy()
        chunks = [q_via[:1]]
        via_sample = [0]
        linear = jacobian(robot, q_via)[:, :3, :]  # (V, 3, n)
        via_speed = [float(np.linalg.norm(linear[0] @ qd))]
        reached = 0 if via_speed[0] >= rated * (1 - SPEED_REACHED) else None
        j = 0
        while reached is None and j < len(q_via) - 1:
            dq = q_via[j + 1] - q_via[j]
            w = np.where(dq >= 0, qd, -qd)
            t_joint = (-w + np.sqrt(w * w + 2.0 * a_max * np.abs(dq))) / a_max  # Eq. 13
            n_acc = max(1, int(np.ceil(float(np.max(t_joint)) / Ts - 1e-9)))  # Eq. 14
            n_steps, speed_bound = self._speed_bounded_steps(linear[j + 1], dq, qd, n_acc, rated)
            tau = n_steps * Ts
            qdd = 2.0 * (dq - qd * tau) / tau**2  # Eq. 15
            t = Ts * np.arange(1, n_steps + 1)[:, None]
            chunk = q_via[j] + qd * t + 0.5 * qdd * t * t  # Eq. 16–17 integrated exactly
            chunk[-1] = q_via[j + 1]
            chunks.append(chunk)
            qd = qd + qdd * tau
            j += 1
            via_sample.append(via_sample[-1] + n_steps)
            via_speed.append(float(np.linalg.norm(linear[j] @ qd)))
            if speed_bound or via_speed[-1] >= rated * (1 - SPEED_REACHED):
                reached = j
        return _Ramp(np.concatenate(chunks), np.array(via_sample), np.array(via_speed), reached)

    def _speed_bounded_steps(
        self, linear: np.ndarray, dq: np.ndarray, qd: np.ndarray, n_acc: int, rated: float
    ) -> tuple[int, bool]:
        """Fewest periods ≥ ``n_acc`` whose end tool speed stays ≤ ``rated`` (inequality 5).

        At the end of an interval of length τ the joint velocity is ``2 Δq / τ − q̇``, so
        the tool velocity is ``a / τ − b`` with ``a = 2 J_v Δq`` and ``b = J_v q̇``.
        """
        a = 2.0 * linear @ dq
        b = linear @ qd

        def end_speed(steps: int) -> float:
            return float(np.linalg.norm(a / (steps * self.Ts) - b))

        if end_speed(n_acc) <= rated:
            return n_acc, False
        aa, ab, bb = float(a @ a), float(a @ b), float(b @ b)
        disc = ab * ab - aa * (bb - rated * rated)
        steps = n_acc
        if aa > 0.0 and disc >= 0.0:
            x = (ab + np.sqrt(disc)) / aa  # largest 1/τ with |a/τ − b| ≤ rated
            if x > 0.0:
                steps = max(n_acc, int(np.ceil(1.0 / (x * self.Ts) - 1e-9)))
        for _ in range(1000):  # round-off at the boundary: a step or two more at most
            if end_speed(steps) <= rated:
                break
            steps += 1
        return steps, True

    # -- arc length of the samples -------------------------------------------------------

    def _arc_lengths(self, q: np.ndarray, owner: np.ndarray) -> np.ndarray:
        """Arc length of each sample's tool point, projected on the piece that made it."""
        p_base = forward_kinematics(self.robot, q)[:, :3, 3]
        R = self.T_base_part[:3, :3]
        p_part = (p_base - self.T_base_part[:3, 3]) @ R
        s = np.empty(len(q))
        for k in np.unique(owner):
            mask = owner == k
            piece = self.pieces[k]
            s[mask] = piece.s_start + self._project(piece, p_part[mask])
        return np.clip(s, 0.0, self.path.length)

    def _project(self, piece, points: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
        """Arc length along one piece of ``points`` (M, 3), m, in [0, piece length]."""
        curve = piece.curve
        sigma, _ = curve.project(points)
        if piece.kind == "arc" and curve.angle >= 2 * np.pi - 1e-9:  # samples in time order
            sigma = unwrap_closed_arc(sigma, 2 * np.pi * curve.radius, piece.length)
        along: np.ndarray = np.clip(sigma, 0.0, piece.length)
        return along


LAW = TimeLaw(Timing.PAPER, "paper", plan_paper_trajectory, follows_joint_path=False)
"""The paper's law, as :data:`trackplan.timing.TIME_LAWS` lists it."""
