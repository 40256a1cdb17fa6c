"""Inverse dynamics against roboticstoolbox and pinocchio, and the parameter conversions."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.conftest import replace_dh
from tests.oracles import oracle, rtb_robot_from
from trackplan.errors import CaseError
from trackplan.robots.dynamics.builtin import puma560_dynamics
from trackplan.robots.dynamics.rne import (
    chain_inverse_dynamics,
    gravity_load,
    inverse_dynamics,
    robot_chain,
)
from trackplan.robots.dynamics_parameters import (
    JointChain,
    Payload,
    RobotDynamics,
    dh_chain,
    inertia_matrix,
    inertia_problem,
)
from trackplan.robots.kinematics import jacobian, joint_frames

rtb = oracle("roboticstoolbox")


def random_states(rng, n_samples, n=6):
    """Random (q, q̇, q̈) with both signs of velocity."""
    q = rng.uniform(-np.pi, np.pi, (n_samples, n))
    qd = rng.uniform(-3.0, 3.0, (n_samples, n))
    qdd = rng.uniform(-10.0, 10.0, (n_samples, n))
    return q, qd, qdd


def rtb_puma_as_robot(puma):
    """Our robot with roboticstoolbox's Puma560 geometry (pedestal d1, d3 = 0.15005)."""
    ref = rtb.models.DH.Puma560()
    d, a, alpha = (np.array([getattr(link, k) for link in ref.links]) for k in ("d", "a", "alpha"))
    return ref, replace_dh(puma, d=d, a=a, alpha=alpha, dynamics=puma560_dynamics(d, a, alpha))


def test_rne_matches_roboticstoolbox_puma560(puma, rng):
    """Rigid body + G² Jm q̈ + friction on 1000 random states, same parameters."""
    ref, robot = rtb_puma_as_robot(puma)
    q, qd, qdd = random_states(rng, 1000)
    expected = ref.rne(q, qd, qdd)
    np.testing.assert_allclose(inverse_dynamics(robot, q, qd, qdd), expected, rtol=1e-9, atol=1e-12)
    # the terms matter: without friction the torques differ by more than round-off
    assert np.abs(inverse_dynamics(robot, q, qd, qdd, friction=False) - expected).max() > 1e-3


def test_rne_matches_roboticstoolbox_on_the_papers_table(puma, rng):
    """The built-in PUMA560 (paper's DH table) against an rtb robot built from the same table."""
    ref = rtb_robot_from(puma)
    q, qd, qdd = random_states(rng, 200)
    np.testing.assert_allclose(
        inverse_dynamics(puma, q, qd, qdd), ref.rne(q, qd, qdd), rtol=1e-9, atol=1e-12
    )


def test_gravity_load_matches_gravload(puma, rng):
    ref, robot = rtb_puma_as_robot(puma)
    q = rng.uniform(-np.pi, np.pi, (300, 6))
    np.testing.assert_allclose(gravity_load(robot, q), ref.gravload(q), rtol=1e-9, atol=1e-12)
    # the base height d1 does not change the torques
    np.testing.assert_allclose(gravity_load(puma, q), gravity_load(robot, q), rtol=0, atol=0.2)


def test_gravity_is_in_the_base_frame(puma, rng):
    """A ceiling-mounted arm (gravity +z) needs the opposite holding torques."""
    q = rng.uniform(-np.pi, np.pi, (50, 6))
    zero = np.zeros_like(q)
    down = inverse_dynamics(puma, q, zero, zero, friction=False)
    up = inverse_dynamics(puma, q, zero, zero, friction=False, gravity=np.array([0, 0, 9.81]))
    np.testing.assert_allclose(up, -down, atol=1e-12)
    assert np.abs(down[:, 1]).max() > 10.0


def test_batched_equals_loop_of_singles(puma, rng):
    q, qd, qdd = (x.reshape(4, 5, 6) for x in random_states(rng, 20))
    batched = inverse_dynamics(puma, q, qd, qdd)
    assert batched.shape == (4, 5, 6)
    for b in range(4):
        for k in range(5):
            np.testing.assert_array_equal(
                batched[b, k], inverse_dynamics(puma, q[b, k], qd[b, k], qdd[b, k])
            )


def test_coulomb_friction_by_sign_of_velocity(puma):
    """At rest no Coulomb term; moving, |G| Tc+ or |G| Tc− on top of G² B q̇."""
    dyn = puma.dynamics
    q = np.zeros((3, 6))
    qd = np.array([[0.0] * 6, [1e-3] * 6, [-1e-3] * 6])
    qdd = np.zeros((3, 6))
    tau = inverse_dynamics(puma, q, qd, qdd) - inverse_dynamics(puma, q, qd, qdd, friction=False)
    G = np.abs(dyn.gear_ratio)
    np.testing.assert_allclose(tau[0], 0.0, atol=1e-12)
    np.testing.assert_allclose(tau[1], G**2 * dyn.viscous * 1e-3 + G * dyn.coulomb[:, 0])
    np.testing.assert_allclose(tau[2], -(G**2) * dyn.viscous * 1e-3 + G * dyn.coulomb[:, 1])


def test_dh_inertials_land_on_the_same_points(puma, rng):
    """Each centre of mass, converted to the child frame, is the same point in the base frame."""
    ref = rtb.models.DH.Puma560()
    com_dh = np.array([link.r for link in ref.links])
    chain = robot_chain(puma)
    for q in rng.uniform(-np.pi, np.pi, (20, 6)):
        dh_frames = joint_frames(puma, q)[1:-1]
        T = np.eye(4)
        for i in range(6):
            c, s = np.cos(q[i]), np.sin(q[i])
            Rz = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
            T = T @ chain.T_parent_joint[i] @ Rz
            com_child = T[:3, :3] @ puma.dynamics.com[i] + T[:3, 3]
            com_dh_base = dh_frames[i][:3, :3] @ com_dh[i] + dh_frames[i][:3, 3]
            np.testing.assert_allclose(com_child, com_dh_base, atol=1e-12)
            inertia_base = T[:3, :3] @ puma.dynamics.inertia[i] @ T[:3, :3].T
            R = dh_frames[i][:3, :3]
            np.testing.assert_allclose(inertia_base, R @ ref.links[i].I @ R.T, atol=1e-12)
        np.testing.assert_allclose(T @ chain.T_last_flange, dh_frames[-1], atol=1e-12)


def test_reexpressed_chain_gives_the_same_torques(puma, rng):
    """Turning every joint frame by a random rotation (axes and inertials with it) is the
    same robot: the kernel handles any axis, not only z."""
    chain = robot_chain(puma)
    dyn = puma.dynamics
    S = np.linalg.qr(rng.normal(size=(6, 3, 3)))[0]
    S *= np.sign(np.linalg.det(S))[:, None, None]
    S4 = np.tile(np.eye(4), (6, 1, 1))
    S4[:, :3, :3] = S
    S4_inv = np.linalg.inv(S4)
    T_parent_joint = chain.T_parent_joint @ S4
    T_parent_joint[1:] = S4_inv[:-1] @ T_parent_joint[1:]
    turned = JointChain(
        T_parent_joint=T_parent_joint,
        axis=np.einsum("nji,nj->ni", S, chain.axis),
        T_last_flange=S4_inv[-1] @ chain.T_last_flange,
    )
    St = np.swapaxes(S, -1, -2)
    turned_dyn = dataclasses.replace(
        dyn, com=np.einsum("nji,nj->ni", S, dyn.com), inertia=St @ dyn.inertia @ S
    )
    q, qd, qdd = random_states(rng, 100)
    np.testing.assert_allclose(
        chain_inverse_dynamics(turned, turned_dyn, q, qd, qdd),
        inverse_dynamics(puma, q, qd, qdd),
        rtol=1e-9,
        atol=1e-9,
    )


def test_payload_holding_torque_is_jacobian_transpose(puma, rng):
    """A point payload adds Jᵀ (m g) at its centre of mass to the holding torques."""
    tool = np.eye(4)
    tool[:3, 3] = [0.02, -0.01, 0.12]
    robot = dataclasses.replace(puma, T_flange_tool=tool)
    com = np.array([0.01, 0.03, 0.05])
    loaded = dataclasses.replace(
        robot,
        dynamics=dataclasses.replace(robot.dynamics, payload=Payload(mass=5.0, com=com)),
    )
    # the Jacobian of the payload's centre of mass: a tool frame moved onto it
    at_com = np.eye(4)
    at_com[:3, 3] = tool[:3, 3] + com
    J = jacobian(dataclasses.replace(robot, T_flange_tool=at_com), q := rng.uniform(-3, 3, (30, 6)))
    extra = gravity_load(loaded, q) - gravity_load(robot, q)
    expected = np.einsum("kin,i->kn", J[:, :3, :], np.array([0.0, 0.0, 5.0 * 9.81]))
    np.testing.assert_allclose(extra, expected, atol=1e-9)


def test_payload_inertia_adds_rotational_torque(puma):
    """A payload's own inertia about the last axis needs I q̈ more at joint 6, reacted
    by joints 1 and 4 whose axes are parallel to it at q = 0."""
    inertia = np.diag([0.01, 0.01, 0.02])
    loaded = dataclasses.replace(
        puma, dynamics=dataclasses.replace(puma.dynamics, payload=Payload(0.0, inertia=inertia))
    )
    qdd = np.array([0, 0, 0, 0, 0, 3.0])
    zero = np.zeros(6)
    diff = inverse_dynamics(loaded, zero, zero, qdd) - inverse_dynamics(puma, zero, zero, qdd)
    np.testing.assert_allclose(diff, [0.06, 0, 0, 0.06, 0, 0.06], atol=1e-12)


def test_rne_matches_pinocchio_on_random_chains(rng):
    """Random chains with unaligned axes and full inertias against pinocchio's rnea."""
    pin = oracle("pinocchio")
    for _ in range(5):
        n = 6
        T = np.tile(np.eye(4), (n, 1, 1))
        T[:, :3, :3] = np.linalg.qr(rng.normal(size=(n, 3, 3)))[0]
        T[:, :3, :3] *= np.sign(np.linalg.det(T[:, :3, :3]))[:, None, None]
        T[:, :3, 3] = rng.uniform(-0.3, 0.3, (n, 3))
        axis = rng.normal(size=(n, 3))
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        chain = JointChain(T_parent_joint=T, axis=axis, T_last_flange=np.eye(4))
        A = rng.normal(size=(n, 3, 3))
        principal = rng.uniform(0.01, 0.1, (n, 3))
        R = np.linalg.qr(A)[0]
        inertia = R @ (principal[:, :, None] * np.eye(3)) @ np.swapaxes(R, -1, -2)
        dyn = RobotDynamics(
            mass=rng.uniform(0.5, 5.0, n),
            com=rng.uniform(-0.2, 0.2, (n, 3)),
            inertia=inertia,
            torque_max=np.full(n, 100.0),
            gravity=np.array([0.3, -2.0, -9.5]),
        )
        model = pin.Model()
        parent = 0
        for i in range(n):
            parent = model.addJoint(
                parent,
                pin.JointModelRevoluteUnaligned(axis[i]),
                pin.SE3(T[i, :3, :3], T[i, :3, 3]),
                f"j{i}",
            )
            model.appendBodyToJoint(
                parent, pin.Inertia(dyn.mass[i], dyn.com[i], dyn.inertia[i]), pin.SE3.Identity()
            )
        model.gravity.linear = dyn.gravity
        data = model.createData()
        q, qd, qdd = random_states(rng, 50, n)
        expected = np.array(
            [pin.rnea(model, data, *state) for state in zip(q, qd, qdd, strict=True)]
        )
        np.testing.assert_allclose(
            chain_inverse_dynamics(chain, dyn, q, qd, qdd), expected, rtol=1e-9, atol=1e-9
        )


def test_dh_chain_is_the_dh_forward_kinematics(puma, rng):
    chain = dh_chain(*puma.dh[:, :3].T, np.array([0.1, -0.2, 0.3, 0, 0.5, -0.4]))
    robot = replace_dh(
        puma, offset=np.array([0.1, -0.2, 0.3, 0, 0.5, -0.4]), dynamics=puma.dynamics
    )
    q = rng.uniform(-3, 3, 6)
    T = np.eye(4)
    for i in range(6):
        c, s = np.cos(q[i]), np.sin(q[i])
        T = (
            T
            @ chain.T_parent_joint[i]
            @ np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
        )
    np.testing.assert_allclose(T @ chain.T_last_flange, joint_frames(robot, q)[-2], atol=1e-12)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"mass": np.array([0, -1.0, 4.8, 0.82, 0.34, 0.09])}, "joints[1].mass: mass must be >= 0"),
        (
            {"torque_max": np.array([97.6, 186.4, 0.0, 24.2, 20.1, 21.3])},
            "joints[2].torque: torque limit must be > 0",
        ),
    ],
)
def test_bad_parameters_are_one_line_errors(puma, change, message):
    with pytest.raises(CaseError) as error:
        dataclasses.replace(puma.dynamics, **change)
    assert error.value.one_line().startswith(message)


def test_inertia_checks():
    assert inertia_problem(inertia_matrix([0.1, 0.2, 0.25, 0, 0, 0])) is None
    assert "triangle" in inertia_problem(inertia_matrix([0.1, 0.1, 0.25, 0, 0, 0]))
    assert inertia_problem(inertia_matrix([0.1, 0.1, 0.25, 0, 0, 0]), triangle=False) is None
    assert "positive semi-definite" in inertia_problem(inertia_matrix([0.1, 0.1, 0.1, 0.2, 0, 0]))
    with pytest.raises(CaseError, match=r"payload\.inertia"):
        Payload(1.0, inertia=inertia_matrix([-0.1, 0.1, 0.1, 0, 0, 0]))
    with pytest.raises(CaseError, match=r"payload\.mass"):
        Payload(-1.0)


def test_kernel_sine_and_cosine_within_one_ulp_of_libm(rng):
    """The vectorised sin/cos of the RNE kernel against numpy's, including the libm fallback."""
    from trackplan.robots.dynamics import _kernels as kernels

    block = kernels.BLOCK
    row = {"q": kernels._Q * block, "cos": kernels._COS * block, "sin": kernels._SIN * block}
    samples = [
        rng.uniform(-np.pi, np.pi, block),
        rng.uniform(-1e5, 1e5, block),
        np.arange(block) * (np.pi / 4) - 4 * np.pi,  # quadrant boundaries
        np.where(np.arange(block) == 3, 2e5, rng.uniform(-10, 10, block)),  # libm for the block
        np.where(np.arange(block) == 5, np.nan, 0.5),
    ]
    for x in samples:
        seg = np.zeros(kernels.SEGMENT)
        seg[row["q"] : row["q"] + block] = x
        kernels._sincos(seg)
        for name, exact in (("cos", np.cos(x)), ("sin", np.sin(x))):
            got = seg[row[name] : row[name] + block]
            ulp = np.spacing(np.maximum(np.abs(exact), np.finfo(float).tiny))
            finite = np.isfinite(x)
            assert np.all(np.abs(got - exact)[finite] <= np.maximum(ulp[finite], 1.2e-16)), name
            assert np.all(np.isnan(got[~finite]))
