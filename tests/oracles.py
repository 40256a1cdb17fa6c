"""Independent oracles shared by several test modules (test-only dependencies)."""

from __future__ import annotations

import warnings
from types import ModuleType

import pytest

PACKAGES = {
    "roboticstoolbox": "roboticstoolbox-python",
    "pinocchio": "pin",
    "py_opw_kinematics": "py-opw-kinematics",
}
"""The oracles' import names and the packages of the ``test`` extra that install them."""


def oracle(name: str) -> ModuleType:
    """The oracle module ``name``, or skip the test with the reason: it is optional.

    The oracles are test-only dependencies (the ``test`` extra of pyproject.toml); a
    test that needs one skips when it is not installed instead of failing.
    """
    package = PACKAGES.get(name, name)
    reason = f"the optional oracle {name} is not installed (pip install {package}; test extra)"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # roboticstoolbox warns about its own imports
        return pytest.importorskip(name, reason=reason)


def rtb_robot_from(robot):  # type: ignore[no-untyped-def]
    """A roboticstoolbox DH robot with ``robot``'s DH table and rtb's Puma560 dynamics.

    Skips the calling test when roboticstoolbox is not installed (:func:`oracle`).
    """
    rtb = oracle("roboticstoolbox")

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
