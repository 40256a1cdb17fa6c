"""Inverse dynamics of a robot, batched over any leading axes (samples, candidates).

``τ = RNE(q, q̇, q̈) + G² Jm q̈ + G² B q̇ + |G| Tc±``: the rigid-body torque plus motor
inertia and friction, as roboticstoolbox computes it for its DH robots (``rne``).
"""

from __future__ import annotations

import numpy as np

from trackplan.derived import derived
from trackplan.robots.dynamics import _kernels as kernels
from trackplan.robots.dynamics_parameters import (
    JointChain,
    RobotDynamics,
    combine_payload,
)
from trackplan.robots.model import Robot


def robot_chain(robot: Robot) -> JointChain:
    """The generic chain of a robot (joint frames, axes and flange).

    Parameters
    ----------
    robot
        Any robot.

    Returns
    -------
    JointChain
    """
    return JointChain(T_parent_joint=robot.origins, axis=robot.axes, T_last_flange=robot.T_tip)


def kernel_constants(
    chain: JointChain, dynamics: RobotDynamics, T_last_tcp: np.ndarray, friction: bool
) -> np.ndarray:
    """The per-joint constant table of :func:`~trackplan.robots.dynamics._kernels.rne_kernel`.

    The payload is merged into the last link; each joint's rotation is split as
    ``R_fixed · Rot(u, q) = R_fixed u uᵀ + cos q · R_fixed (I − u uᵀ) + sin q · R_fixed [u]×``;
    inertias are moved to the joint origins (parallel-axis theorem).

    Parameters
    ----------
    chain
        Joint frames and axes.
    dynamics
        Inertials in the chain's child frames, actuators, friction.
    T_last_tcp
        The TCP in the last joint's child frame, shape (4, 4) (where the payload sits).
    friction
        Include viscous and Coulomb friction.

    Returns
    -------
    numpy.ndarray
        Shape (n, ``N_CONSTANTS``).
    """
    mass = np.array(dynamics.mass)
    com = np.array(dynamics.com)
    inertia = np.array(dynamics.inertia)
    if dynamics.payload is not None:
        mass[-1], com[-1], inertia[-1] = combine_payload(
            mass[-1], com[-1], inertia[-1], dynamics.payload, T_last_tcp
        )
    n = len(mass)
    u = np.asarray(chain.axis, dtype=float)
    R_fixed = np.asarray(chain.T_parent_joint, dtype=float)[:, :3, :3]
    uu = u[:, :, None] * u[:, None, :]
    skew = np.zeros((n, 3, 3))
    skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 2] = -u[:, 2], u[:, 1], -u[:, 0]
    skew -= np.swapaxes(skew, -1, -2)
    inertia_origin = inertia + mass[:, None, None] * (
        np.einsum("ni,ni->n", com, com)[:, None, None] * np.eye(3)
        - com[:, :, None] * com[:, None, :]
    )
    G = np.asarray(dynamics.gear_ratio)
    coulomb = np.asarray(dynamics.coulomb) * np.abs(G)[:, None]
    scale = 1.0 if friction else 0.0
    K = np.zeros((n, kernels.N_CONSTANTS))
    K[:, kernels.ROT_FIXED : kernels.ROT_FIXED + 9] = (R_fixed @ uu).reshape(n, 9)
    K[:, kernels.ROT_COS : kernels.ROT_COS + 9] = (R_fixed @ (np.eye(3) - uu)).reshape(n, 9)
    K[:, kernels.ROT_SIN : kernels.ROT_SIN + 9] = (R_fixed @ skew).reshape(n, 9)
    K[:, kernels.ORIGIN : kernels.ORIGIN + 3] = np.asarray(chain.T_parent_joint)[:, :3, 3]
    K[:, kernels.AXIS : kernels.AXIS + 3] = u
    K[:, kernels.MASS] = mass
    K[:, kernels.MOMENT : kernels.MOMENT + 3] = mass[:, None] * com
    rows, cols = (0, 1, 2, 0, 1, 0), (0, 1, 2, 1, 2, 2)
    K[:, kernels.INERTIA : kernels.INERTIA + 6] = inertia_origin[:, rows, cols]
    K[:, kernels.ARMATURE] = G**2 * np.asarray(dynamics.motor_inertia)
    K[:, kernels.VISCOUS] = scale * G**2 * np.asarray(dynamics.viscous)
    K[:, kernels.COULOMB_POS] = scale * coulomb[:, 0]
    K[:, kernels.COULOMB_NEG] = scale * coulomb[:, 1]
    return K


def chain_inverse_dynamics(
    chain: JointChain,
    dynamics: RobotDynamics,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    *,
    T_flange_tcp: np.ndarray | None = None,
    friction: bool = True,
    gravity: np.ndarray | None = None,
) -> np.ndarray:
    """Joint torques of a generic chain, link side.

    Parameters
    ----------
    chain
        Joint frames and axes.
    dynamics
        Inertials in the chain's child frames, actuators, friction, gravity, payload.
    q, qd, qdd
        Joint positions, velocities and accelerations, shape (..., n), rad, rad/s, rad/s².
    T_flange_tcp
        The TCP in the flange frame, shape (4, 4) (where the payload sits); default identity.
    friction
        Include viscous and Coulomb friction.
    gravity
        Gravity in the base frame, shape (3,), m/s²; default ``dynamics.gravity``.

    Returns
    -------
    numpy.ndarray
        τ, shape (..., n), N·m.
    """
    T_tool = np.eye(4) if T_flange_tcp is None else np.asarray(T_flange_tcp, dtype=float)
    K = kernel_constants(chain, dynamics, chain.T_last_flange @ T_tool, friction)
    return _torques(K, dynamics.gravity if gravity is None else gravity, q, qd, qdd)


def _torques(
    K: np.ndarray, gravity: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray
) -> np.ndarray:
    """Run the kernel over states of any leading shape."""
    g = np.array(gravity, dtype=float)
    q, qd, qdd = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (q, qd, qdd)))
    shape = q.shape
    q_flat, qd_flat, qdd_flat = (_read_only(x.reshape(-1, shape[-1])) for x in (q, qd, qdd))
    tau = np.empty(q_flat.shape)
    kernels.rne_kernel(K, g, q_flat, qd_flat, qdd_flat, tau)
    return tau.reshape(shape)


def _read_only(x: np.ndarray) -> np.ndarray:
    """A C-contiguous read-only view (a copy where x is not contiguous) of x.

    numba compiles one specialisation per writable flag: the search passes fresh arrays,
    a plan its frozen result's, and each specialisation is a kernel more to load from the
    cache in every process. Read-only inputs whatever the caller's give one.
    """
    view = np.ascontiguousarray(x).view()
    view.flags.writeable = False
    return view


def inverse_dynamics(
    robot: Robot,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    *,
    friction: bool = True,
    gravity: np.ndarray | None = None,
) -> np.ndarray:
    """Joint torques needed for a motion, link side.

    Parameters
    ----------
    robot
        A robot with :attr:`~trackplan.robots.model.Robot.dynamics`.
    q, qd, qdd
        Joint positions, velocities and accelerations, shape (..., n), rad, rad/s, rad/s²
        (batch axes first: candidates, samples).
    friction
        Include viscous and Coulomb friction.
    gravity
        Gravity in the base frame, shape (3,), m/s²; default the robot's.

    Returns
    -------
    numpy.ndarray
        τ, shape (..., n), N·m.

    Raises
    ------
    ValueError
        When the robot has no dynamic parameters.
    """
    dynamics = _require(robot)
    return _torques(
        _robot_constants(robot, friction),
        dynamics.gravity if gravity is None else gravity,
        q,
        qd,
        qdd,
    )


def _robot_constants(robot: Robot, friction: bool) -> np.ndarray:
    """The kernel constants of a robot with dynamics, computed once per robot object."""

    def build() -> np.ndarray:
        chain = robot_chain(robot)
        return kernel_constants(
            chain, _require(robot), chain.T_last_flange @ robot.T_flange_tool, friction
        )

    return derived(robot, ("rne constants", friction), build)


def gravity_load(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Torques that hold the robot still at ``q`` against gravity (no friction), N·m.

    Parameters
    ----------
    robot
        A robot with dynamics.
    q
        Joint positions, shape (..., n), rad.

    Returns
    -------
    numpy.ndarray
        Shape (..., n), N·m.
    """
    zero = np.zeros_like(np.asarray(q, dtype=float))
    return inverse_dynamics(robot, q, zero, zero, friction=False)


def _require(robot: Robot) -> RobotDynamics:
    """The robot's dynamics, or a clear error."""
    if robot.dynamics is None:
        raise ValueError(f"robot {robot.name!r} has no dynamic parameters")
    return robot.dynamics


def holding_torque_ratio(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Largest gravity-holding torque over the torque limit, along joint paths.

    Above 1 the robot cannot hold the path's poses against gravity: no speed helps.

    Parameters
    ----------
    robot
        A robot with dynamics.
    q
        Joint paths, shape (..., M, n), rad; NaN entries (poses without a solution) count
        as no load.

    Returns
    -------
    numpy.ndarray
        ``max_k max_i |τ_g,i(q_k)| / τ_max,i``, shape (...).
    """
    dynamics = _require(robot)
    q = np.asarray(q, dtype=float)
    finite = np.isfinite(q).all(axis=-1, keepdims=True)
    holding = gravity_load(robot, np.where(finite, q, 0.0))
    ratio = np.where(finite, np.abs(holding) / dynamics.torque_max, 0.0)
    largest: np.ndarray = ratio.max(axis=(-2, -1))
    return largest
