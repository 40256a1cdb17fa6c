"""Free profiles: a quantity the planner chooses along the path, and one chosen curve of it.

A :class:`FreeProfile` is the data of one free degree of freedom: how many nodes (B-spline
coefficients over the path parameter s) it has, the bounds of each node, the largest rate
|d value / ds|, and the map between the search's decision variables and the nodes. A
:class:`Profile` is one chosen curve: its coefficients over [0, length], evaluated with its
derivatives. The tool's spin is one free profile (:meth:`trackplan.tool.ToolSpec.spin_profile`);
external axes and a 7-joint arm's arm angle are described by the same data.

Three kinds, by the number of nodes:

- 0 nodes: fixed at :attr:`FreeProfile.fixed`, no decision variable;
- 1 node: one constant in ``[lower, upper]``, one decision variable (the value);
- k ≥ 4 nodes: a clamped cubic B-spline on uniform knots; the first variable is the first
  node and each further one, in [−1, 1], the step to the next node as a share of the largest
  step :attr:`FreeProfile.rate` allows; each running node is clipped to its bounds and to the
  rate's reach, so every step stays within the rate bound. By the convex-hull property the
  curve's rate stays below :attr:`FreeProfile.rate` and, with nodes within their bounds, the
  curve between the smallest and the largest node.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from trackplan.profiles.bspline import (
    DEGREE,
    MAX_ORDER,
    clamped_knots,
    increment_spans,
    profile_values,
)


@dataclass(frozen=True, eq=False)
class Profile:
    """One chosen curve of a free profile over the path parameter s ∈ [0, length].

    One coefficient: a constant. More: a clamped cubic B-spline on uniform knots over
    [0, length]; by the convex-hull property it stays between the smallest and the largest
    coefficient and its rate below :attr:`max_rate`.

    Attributes
    ----------
    coefficients
        Shape (k,), in the profile's unit (rad for the spin).
    length
        Length of the path the profile spans, m.
    """

    coefficients: np.ndarray
    length: float

    @classmethod
    def constant(cls, value: float, length: float) -> Profile:
        """A constant profile at ``value``."""
        return cls(np.array([float(value)]), float(length))

    @property
    def knots(self) -> np.ndarray:
        """Knot vector in s, shape (k + 4,), m (empty for a constant)."""
        return clamped_knots(len(self.coefficients), self.length)

    @property
    def max_rate(self) -> float:
        """Bound of |d value / ds| from the coefficients (convex hull), unit / m."""
        if len(self.coefficients) == 1:
            return 0.0
        steps = np.abs(np.diff(self.coefficients))
        return float(np.max(steps / increment_spans(len(self.coefficients), self.length)))

    def derivative(self, s: np.ndarray, order: int) -> np.ndarray:
        """The value (order 0) or its first or second derivative in s at ``s`` (M,), shape (M,)."""
        if order == 0:
            values: np.ndarray = profile_values(self.coefficients[None], s, self.length)[0]
            return values
        s = np.asarray(s, dtype=float)
        if len(self.coefficients) == 1 or not 0 < order <= MAX_ORDER:
            constant: np.ndarray = profile_values(self.coefficients[None], s, self.length, order)[0]
            return constant
        from scipy.interpolate import BSpline  # only varying profiles need scipy (startup time)

        # one curve: scipy's derivative spline, cheaper than a design matrix per call
        spline = BSpline(self.knots, self.coefficients, DEGREE).derivative(order)
        rates: np.ndarray = spline(np.clip(s, 0.0, self.length))
        return rates

    def value(self, s: np.ndarray) -> np.ndarray:
        """The profile at path parameters ``s`` (M,), shape (M,)."""
        return self.derivative(s, 0)

    def rate(self, s: np.ndarray) -> np.ndarray:
        """d value / ds at path parameters ``s`` (M,), shape (M,), unit / m."""
        return self.derivative(s, 1)

    def as_dict(self) -> dict[str, object]:
        """``{value}`` or ``{knots, coefficients, degree}`` for result files."""
        if len(self.coefficients) == 1:
            return {"value": float(self.coefficients[0])}
        return {
            "knots": self.knots.tolist(),
            "coefficients": self.coefficients.tolist(),
            "degree": DEGREE,
        }


@dataclass(frozen=True, eq=False)
class FreeProfile:
    """A degree of freedom the planner chooses along the path: nodes, bounds, rate.

    Attributes
    ----------
    nodes
        Number of nodes: 0 (fixed), 1 (one constant) or at least ``DEGREE + 1`` (a
        B-spline over s).
    lower, upper
        Bounds of each node, shape (max(nodes, 1),); a scalar is the same for every node.
    rate
        Largest |d value / ds| of a varying profile, unit / m (finite, > 0).
    fixed
        The value of a profile with no nodes.
    """

    nodes: int
    lower: np.ndarray
    upper: np.ndarray
    rate: float = np.inf
    fixed: float = 0.0

    def __post_init__(self) -> None:
        if self.nodes < 0 or 1 < self.nodes <= DEGREE:
            raise ValueError(f"a free profile has 0, 1 or at least {DEGREE + 1} nodes")
        if self.nodes > 1 and not 0.0 < self.rate < np.inf:
            raise ValueError(f"a varying free profile needs a finite rate > 0, not {self.rate}")
        shape = (max(self.nodes, 1),)
        lower = np.broadcast_to(np.asarray(self.lower, dtype=float), shape).copy()
        upper = np.broadcast_to(np.asarray(self.upper, dtype=float), shape).copy()
        object.__setattr__(self, "lower", lower)
        object.__setattr__(self, "upper", upper)

    @property
    def n_variables(self) -> int:
        """Number of decision variables: the number of nodes."""
        return self.nodes

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Box of the decision variables (see :meth:`coefficients`), each shape (n_variables,)."""
        if self.nodes <= 1:
            return self.lower[: self.nodes].copy(), self.upper[: self.nodes].copy()
        ones = np.ones(self.nodes - 1)
        return np.concatenate([self.lower[:1], -ones]), np.concatenate([self.upper[:1], ones])

    def coefficients(self, variables: np.ndarray, length: float) -> np.ndarray:
        """Nodes of B sets of decision variables.

        Each node after the first is clipped to its bounds and to the rate's reach from the
        node before; where the two do not meet (bounds of neighbouring nodes farther apart
        than the rate can go) the rate wins and the node ends as near its bounds as the
        rate allows (:meth:`outside_bounds` tells). With the same bounds for every node
        this is the running sum clipped to the bounds.

        Parameters
        ----------
        variables
            Shape (B, n_variables).
        length
            Length of the path, m.

        Returns
        -------
        numpy.ndarray
            Shape (B, max(nodes, 1)).
        """
        variables = np.atleast_2d(np.asarray(variables, dtype=float))
        if self.nodes == 0:
            return np.full((len(variables), 1), self.fixed)
        if self.nodes == 1:
            return variables[:, :1].copy()
        spans = increment_spans(self.nodes, length)
        steps = variables[:, 1:] * self.rate * spans
        reach = self.rate * spans
        running = [np.clip(variables[:, 0], self.lower[0], self.upper[0])]
        for i in range(1, self.nodes):  # the clip depends on the clipped predecessor
            previous = running[-1]
            node = np.clip(previous + steps[:, i - 1], self.lower[i], self.upper[i])
            running.append(np.clip(node, previous - reach[i - 1], previous + reach[i - 1]))
        return np.stack(running, axis=1)

    def variables(self, coefficients: np.ndarray, length: float) -> np.ndarray:
        """Decision variables nearest to the given nodes (B, k), shape (B, n_variables)."""
        c = np.atleast_2d(np.asarray(coefficients, dtype=float))
        if self.nodes <= 1:
            return c[:, : self.nodes].copy()
        spans = self.rate * increment_spans(self.nodes, length)
        return np.concatenate([c[:, :1], np.clip(np.diff(c, axis=1) / spans, -1, 1)], axis=1)

    def default_variables(self) -> np.ndarray:
        """Variables of a constant in the middle of the first node's range, (n_variables,)."""
        middle = 0.5 * (self.lower[0] + self.upper[0])
        if self.nodes <= 1:
            return np.full(self.nodes, middle)
        return np.concatenate([[middle], np.zeros(self.nodes - 1)])

    def profile(self, variables: np.ndarray | None, length: float) -> Profile:
        """The curve of one set of variables (n_variables,); None: :meth:`default_variables`."""
        if variables is None:
            variables = self.default_variables()
        coefficients = self.coefficients(np.asarray(variables, dtype=float)[None], length)
        return Profile(coefficients[0], float(length))

    def values(
        self, variables: np.ndarray, s: np.ndarray, length: float, order: int = 0
    ) -> np.ndarray:
        """The curves of B sets of variables (B, n_variables) at s (M,), shape (B, M).

        ``order`` 1 or 2 gives the first or second derivative in s instead.
        """
        return profile_values(self.coefficients(variables, length), s, length, order)

    def outside_bounds(self, coefficients: np.ndarray, tolerance: float = 1e-12) -> bool:
        """Whether given nodes (k,) leave the bounds (by more than ``tolerance``).

        Nodes of another count than :attr:`nodes` are held to the bounds when those are the
        same for every node, and are outside otherwise.
        """
        c = np.asarray(coefficients, dtype=float)
        lower, upper = self.lower, self.upper
        if c.shape != lower.shape:
            if np.ptp(lower) > 0.0 or np.ptp(upper) > 0.0:
                return True
            lower, upper = lower[:1], upper[:1]
        return bool(np.any(c < lower - tolerance) or np.any(c > upper + tolerance))
