"""Independent oracles shared by several test modules (test-only dependencies)."""

from __future__ import annotations


def rtb_robot_from(robot):  # type: ignore[no-untyped-def]
    """A roboticstoolbox DH robot with ``robot``'s DH table and rtb's Puma560 dynamics.

    The caller skips when roboticstoolbox is missing (``pytest.importorskip``).
    """
    import roboticstoolbox as rtb

    ref = rtb.models.DH.Puma560()
    return rtb.DHRobot(
        [
            rtb.RevoluteDH(
                d=robot.dh[i, 0],
                a=robot.dh[i, 1],
                alpha=robot.dh[i, 2],
                offset=robot.dh[i, 3],
                m=link.m,
                r=link.r,
                I=link.I,
                Jm=link.Jm,
                G=link.G,
                B=link.B,
                Tc=link.Tc,
            )
            for i, link in enumerate(ref.links)
        ]
    )
