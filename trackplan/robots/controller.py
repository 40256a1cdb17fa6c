"""How a robot's controller counts its joints and where it puts its world frame.

A controller may count a joint with another zero, sign or coupling than the robot model,
and may put its world frame elsewhere than the model's base. :class:`ControllerConvention`
states that mapping for one robot; the program writers (:mod:`trackplan.writers`) write
joint targets, turns and configuration fields in it, and Cartesian frames in its world.

The map from model joints q (rad) to controller joints θ (rad) is affine::

    θ = signs · q + offsets,   then   θ[coupled] += factor · q[driver]

(a parallel-arm or FANUC J2/J3 coupling), and it inverts exactly. ``docs/export.md`` lists
each built-in robot's convention with its source.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

VENDORS = ("kuka", "abb", "fanuc", "ur", "generic")
"""Controller families a robot file may name; ``generic`` drives none by default."""


@dataclass(frozen=True, eq=False, kw_only=True)
class ControllerConvention:
    """A robot controller's joint convention and world frame.

    Attributes
    ----------
    vendor
        One of :data:`VENDORS`; the program formats check it (URScript drives ``ur`` only).
    signs
        Per-joint sign (+1 or −1) from the model's joint to the controller's, shape (n,).
    offsets
        Per-joint offset added after the sign, shape (n,), rad.
    coupling
        ``(coupled, driver, factor)`` with 0-based joint indices: the controller's
        ``coupled`` joint adds ``factor`` · the model's ``driver`` joint (rad per rad),
        or None for a serial count.
    world
        The controller's world (robot base) frame in the model's base frame, shape
        (4, 4), m: e.g. the FANUC world at J2 height, a UR base turned by π about z.
    source
        Where the convention comes from (shown in the program headers and docs).
    cycle
        The controller's interpolation (servo) step, s, when it matters to a program
        (URScript ``servoj``: 0.002 on UR e-Series, 0.008 on CB3), else None.
    """

    vendor: str = "generic"
    signs: np.ndarray
    offsets: np.ndarray
    coupling: tuple[int, int, float] | None = None
    world: np.ndarray = field(default_factory=lambda: np.eye(4))
    source: str = ""
    cycle: float | None = None

    @classmethod
    def identity(
        cls, n_dof: int, vendor: str = "generic", source: str = ""
    ) -> ControllerConvention:
        """The controller counts every joint as the model does; its world is the base."""
        return cls(
            vendor=vendor,
            signs=np.ones(n_dof),
            offsets=np.zeros(n_dof),
            source=source or "identity: no controller convention given",
        )

    @property
    def n_dof(self) -> int:
        """Number of joints."""
        return int(self.signs.shape[0])

    @property
    def is_identity(self) -> bool:
        """True when controller joints equal model joints and the world is the base."""
        return (
            bool(np.all(self.signs == 1.0))
            and not np.any(self.offsets)
            and self.coupling is None
            and bool(np.array_equal(self.world, np.eye(4)))
        )

    def to_controller(self, q: np.ndarray) -> np.ndarray:
        """Controller joints θ of model joints q.

        Parameters
        ----------
        q
            Model joint positions, shape (..., n), rad.

        Returns
        -------
        numpy.ndarray
            θ, shape (..., n), rad.
        """
        q = np.asarray(q, dtype=float)
        theta: np.ndarray = self.signs * q + self.offsets
        if self.coupling is not None:
            coupled, driver, factor = self.coupling
            theta[..., coupled] += factor * q[..., driver]
        return theta

    def to_model(self, theta: np.ndarray) -> np.ndarray:
        """Model joints q of controller joints θ (the inverse of :meth:`to_controller`).

        Parameters
        ----------
        theta
            Controller joint positions, shape (..., n), rad.

        Returns
        -------
        numpy.ndarray
            q, shape (..., n), rad.
        """
        theta = np.array(theta, dtype=float)
        if self.coupling is not None:
            coupled, driver, factor = self.coupling
            q_driver = (theta[..., driver] - self.offsets[driver]) / self.signs[driver]
            theta[..., coupled] -= factor * q_driver
        q: np.ndarray = (theta - self.offsets) / self.signs
        return q

    def world_from_base(self, pose: np.ndarray) -> np.ndarray:
        """A pose given in the model's base frame, expressed in the controller's world.

        Parameters
        ----------
        pose
            Shape (..., 4, 4), m.

        Returns
        -------
        numpy.ndarray
            ``world⁻¹ · pose``, shape (..., 4, 4), m.
        """
        inverse: np.ndarray = np.linalg.inv(self.world)
        expressed: np.ndarray = inverse @ pose
        return expressed


__all__ = ["VENDORS", "ControllerConvention"]
