"""Compiled recursive Newton–Euler inverse dynamics over a generic serial chain.

Conventions are those of :mod:`trackplan.robots.dynamics.parameters`: joint i at
``T_parent_joint[i]`` in the child frame of joint i-1, turning about ``axis[i]``; link
inertials in the child frames. Every quantity of the recursion is kept in the child frame of
its link (Luh, Walker and Paul's "outward" form), so no world-frame transform is built.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy", fastmath={"contract", "reassoc"})
def rne_kernel(
    T_parent_joint: np.ndarray,
    axis: np.ndarray,
    mass: np.ndarray,
    com: np.ndarray,
    inertia: np.ndarray,
    gravity: np.ndarray,
    armature: np.ndarray,
    viscous: np.ndarray,
    coulomb_pos: np.ndarray,
    coulomb_neg: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    out: np.ndarray,
) -> None:
    """Joint torques ``τ = RNE(q, q̇, q̈) + armature·q̈ + viscous·q̇ + Coulomb(q̇)``.

    Parameters
    ----------
    T_parent_joint
        Shape (n, 4, 4).
    axis
        Unit joint axes in the joint frames, shape (n, 3).
    mass, com, inertia
        Link inertials in the child frames: (n,) kg, (n, 3) m, (n, 3, 3) kg·m² about the
        centre of mass.
    gravity
        Gravity in the base frame, shape (3,), m/s².
    armature
        ``G² Jm``, shape (n,), kg·m².
    viscous
        ``G² B``, shape (n,), N·m·s/rad.
    coulomb_pos, coulomb_neg
        ``|G| Tc+`` and ``|G| Tc−``, shape (n,), N·m.
    q, qd, qdd
        Joint states, shape (N, n), rad, rad/s, rad/s².
    out
        Torques, shape (N, n), N·m (written).
    """
    n = q.shape[1]
    R = np.empty((n, 3, 3))  # rotation of child frame i in the previous child frame
    w = np.empty(3)
    wd = np.empty(3)
    vd = np.empty(3)
    F = np.empty((n, 3))
    Nm = np.empty((n, 3))
    f = np.empty(3)
    tq = np.empty(3)
    for k in range(q.shape[0]):
        w[:] = 0.0
        wd[:] = 0.0
        vd[0] = -gravity[0]
        vd[1] = -gravity[1]
        vd[2] = -gravity[2]
        for i in range(n):
            ux, uy, uz = axis[i, 0], axis[i, 1], axis[i, 2]
            c = np.cos(q[k, i])
            s = np.sin(q[k, i])
            if ux == 0.0 and uy == 0.0 and uz == 1.0:
                # R_i = R_fixed · Rz(q): the common case (every DH joint), a third of the work
                for a in range(3):
                    f0 = T_parent_joint[i, a, 0]
                    f1 = T_parent_joint[i, a, 1]
                    R[i, a, 0] = f0 * c + f1 * s
                    R[i, a, 1] = f1 * c - f0 * s
                    R[i, a, 2] = T_parent_joint[i, a, 2]
            else:
                # R_i = R_fixed · Rot(axis, q) (Rodrigues)
                v = 1.0 - c
                r00 = c + ux * ux * v
                r01 = ux * uy * v - uz * s
                r02 = ux * uz * v + uy * s
                r10 = uy * ux * v + uz * s
                r11 = c + uy * uy * v
                r12 = uy * uz * v - ux * s
                r20 = uz * ux * v - uy * s
                r21 = uz * uy * v + ux * s
                r22 = c + uz * uz * v
                for a in range(3):
                    f0 = T_parent_joint[i, a, 0]
                    f1 = T_parent_joint[i, a, 1]
                    f2 = T_parent_joint[i, a, 2]
                    R[i, a, 0] = f0 * r00 + f1 * r10 + f2 * r20
                    R[i, a, 1] = f0 * r01 + f1 * r11 + f2 * r21
                    R[i, a, 2] = f0 * r02 + f1 * r12 + f2 * r22
            px = T_parent_joint[i, 0, 3]
            py = T_parent_joint[i, 1, 3]
            pz = T_parent_joint[i, 2, 3]
            # linear acceleration of the joint origin, previous frame
            ax = wd[1] * pz - wd[2] * py
            ay = wd[2] * px - wd[0] * pz
            az = wd[0] * py - wd[1] * px
            cx = w[1] * pz - w[2] * py
            cy = w[2] * px - w[0] * pz
            cz = w[0] * py - w[1] * px
            ax += w[1] * cz - w[2] * cy + vd[0]
            ay += w[2] * cx - w[0] * cz + vd[1]
            az += w[0] * cy - w[1] * cx + vd[2]
            # into the child frame: x_child = R^T x_prev
            wx = R[i, 0, 0] * w[0] + R[i, 1, 0] * w[1] + R[i, 2, 0] * w[2]
            wy = R[i, 0, 1] * w[0] + R[i, 1, 1] * w[1] + R[i, 2, 1] * w[2]
            wz = R[i, 0, 2] * w[0] + R[i, 1, 2] * w[1] + R[i, 2, 2] * w[2]
            bx = R[i, 0, 0] * wd[0] + R[i, 1, 0] * wd[1] + R[i, 2, 0] * wd[2]
            by = R[i, 0, 1] * wd[0] + R[i, 1, 1] * wd[1] + R[i, 2, 1] * wd[2]
            bz = R[i, 0, 2] * wd[0] + R[i, 1, 2] * wd[1] + R[i, 2, 2] * wd[2]
            vd[0] = R[i, 0, 0] * ax + R[i, 1, 0] * ay + R[i, 2, 0] * az
            vd[1] = R[i, 0, 1] * ax + R[i, 1, 1] * ay + R[i, 2, 1] * az
            vd[2] = R[i, 0, 2] * ax + R[i, 1, 2] * ay + R[i, 2, 2] * az
            # w_i = R^T w + u q̇; ẇ_i = R^T ẇ + u q̈ + (R^T w) × u q̇
            dq = qd[k, i]
            ddq = qdd[k, i]
            wd[0] = bx + ux * ddq + (wy * uz - wz * uy) * dq
            wd[1] = by + uy * ddq + (wz * ux - wx * uz) * dq
            wd[2] = bz + uz * ddq + (wx * uy - wy * ux) * dq
            w[0] = wx + ux * dq
            w[1] = wy + uy * dq
            w[2] = wz + uz * dq
            # acceleration of the centre of mass, force and moment about it
            rx, ry, rz = com[i, 0], com[i, 1], com[i, 2]
            cx = w[1] * rz - w[2] * ry
            cy = w[2] * rx - w[0] * rz
            cz = w[0] * ry - w[1] * rx
            m = mass[i]
            F[i, 0] = m * (wd[1] * rz - wd[2] * ry + w[1] * cz - w[2] * cy + vd[0])
            F[i, 1] = m * (wd[2] * rx - wd[0] * rz + w[2] * cx - w[0] * cz + vd[1])
            F[i, 2] = m * (wd[0] * ry - wd[1] * rx + w[0] * cy - w[1] * cx + vd[2])
            Iw0 = inertia[i, 0, 0] * w[0] + inertia[i, 0, 1] * w[1] + inertia[i, 0, 2] * w[2]
            Iw1 = inertia[i, 1, 0] * w[0] + inertia[i, 1, 1] * w[1] + inertia[i, 1, 2] * w[2]
            Iw2 = inertia[i, 2, 0] * w[0] + inertia[i, 2, 1] * w[1] + inertia[i, 2, 2] * w[2]
            Nm[i, 0] = (
                inertia[i, 0, 0] * wd[0]
                + inertia[i, 0, 1] * wd[1]
                + inertia[i, 0, 2] * wd[2]
                + w[1] * Iw2
                - w[2] * Iw1
            )
            Nm[i, 1] = (
                inertia[i, 1, 0] * wd[0]
                + inertia[i, 1, 1] * wd[1]
                + inertia[i, 1, 2] * wd[2]
                + w[2] * Iw0
                - w[0] * Iw2
            )
            Nm[i, 2] = (
                inertia[i, 2, 0] * wd[0]
                + inertia[i, 2, 1] * wd[1]
                + inertia[i, 2, 2] * wd[2]
                + w[0] * Iw1
                - w[1] * Iw0
            )
        # backward: force f and moment tq on link i at its origin, child frame i
        f[:] = 0.0
        tq[:] = 0.0
        for i in range(n - 1, -1, -1):
            if i < n - 1:
                # the next link's wrench into this frame, moment carried to this origin
                gx = R[i + 1, 0, 0] * f[0] + R[i + 1, 0, 1] * f[1] + R[i + 1, 0, 2] * f[2]
                gy = R[i + 1, 1, 0] * f[0] + R[i + 1, 1, 1] * f[1] + R[i + 1, 1, 2] * f[2]
                gz = R[i + 1, 2, 0] * f[0] + R[i + 1, 2, 1] * f[1] + R[i + 1, 2, 2] * f[2]
                hx = R[i + 1, 0, 0] * tq[0] + R[i + 1, 0, 1] * tq[1] + R[i + 1, 0, 2] * tq[2]
                hy = R[i + 1, 1, 0] * tq[0] + R[i + 1, 1, 1] * tq[1] + R[i + 1, 1, 2] * tq[2]
                hz = R[i + 1, 2, 0] * tq[0] + R[i + 1, 2, 1] * tq[1] + R[i + 1, 2, 2] * tq[2]
                px = T_parent_joint[i + 1, 0, 3]
                py = T_parent_joint[i + 1, 1, 3]
                pz = T_parent_joint[i + 1, 2, 3]
                hx += py * gz - pz * gy
                hy += pz * gx - px * gz
                hz += px * gy - py * gx
            else:
                gx = gy = gz = hx = hy = hz = 0.0
            rx, ry, rz = com[i, 0], com[i, 1], com[i, 2]
            tq[0] = hx + Nm[i, 0] + ry * F[i, 2] - rz * F[i, 1]
            tq[1] = hy + Nm[i, 1] + rz * F[i, 0] - rx * F[i, 2]
            tq[2] = hz + Nm[i, 2] + rx * F[i, 1] - ry * F[i, 0]
            f[0] = gx + F[i, 0]
            f[1] = gy + F[i, 1]
            f[2] = gz + F[i, 2]
            dq = qd[k, i]
            friction = viscous[i] * dq
            if dq > 0.0:
                friction += coulomb_pos[i]
            elif dq < 0.0:
                friction += coulomb_neg[i]
            out[k, i] = (
                tq[0] * axis[i, 0]
                + tq[1] * axis[i, 1]
                + tq[2] * axis[i, 2]
                + armature[i] * qdd[k, i]
                + friction
            )
