"""What the joint path asks of the joints at a path speed: speed caps and speed-change bounds.

Along the path the joints move as ``q(s)``; at path speed ``v = ṡ``, acceleration ``a = s̈``
and jerk ``j = s⃛`` the joint velocity, acceleration and jerk are

    q̇ = q' v,    q̈ = q' a + q'' v²,    q⃛ = q' j + 3 q'' v a + q''' v³

(``'`` is d/ds). A :class:`ZoneDemand` holds the signed q', q'', q''' on a zone's grid and
turns them into

- the highest constant speed each grid point allows (:meth:`ZoneDemand.local_caps`), and
- the acceleration and jerk bounds of one jerk-limited speed change across the stretch it
  covers (:func:`speed_change`), with the speed the change actually has at each grid point,
  not its top speed everywhere.
"""

from __future__ import annotations

import math
from dataclasses import InitVar, dataclass, field

import numpy as np

from trackplan.robots.machine import Machine
from trackplan.robots.model import Robot
from trackplan.timing import _kernels, _kernels_samples
from trackplan.timing._kernels import MAX_PATH_ACCELERATION, MAX_PATH_JERK


def safe_ratio(numerator: np.ndarray, denominator: np.ndarray) -> np.ndarray:
    """numerator / denominator with +inf where the denominator is zero."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out = np.asarray(numerator / denominator, dtype=float)
    return np.where(denominator > 0, out, np.inf)


@dataclass(frozen=True, eq=False)
class ZoneDemand:
    """Signed joint-path derivatives on one zone's grid.

    Attributes
    ----------
    s
        Grid, shape (G,), m, increasing.
    d1, d2, d3
        dq/ds, d²q/ds², d³q/ds³ at the grid, shape (G, n), rad/m, rad/m², rad/m³.
    magnitudes
        |d1|, |d2|, |d3| when already taken (a zone's part reads its zone's); default:
        taken here.
    """

    s: np.ndarray
    d1: np.ndarray
    d2: np.ndarray
    d3: np.ndarray
    magnitudes: InitVar[tuple[np.ndarray, np.ndarray, np.ndarray] | None] = None
    _abs: tuple[np.ndarray, np.ndarray, np.ndarray] = field(init=False, repr=False)
    _peaks: tuple[np.ndarray, np.ndarray, np.ndarray] = field(init=False, repr=False)
    _peak_array: np.ndarray = field(init=False, repr=False)
    _maxima: list[np.ndarray | None] = field(init=False, repr=False)

    def __post_init__(self, magnitudes: tuple[np.ndarray, np.ndarray, np.ndarray] | None) -> None:
        absolute = magnitudes or (np.abs(self.d1), np.abs(self.d2), np.abs(self.d3))
        object.__setattr__(self, "_abs", absolute)
        object.__setattr__(self, "_peaks", tuple(d.max(axis=0) for d in absolute))
        object.__setattr__(self, "_peak_array", np.stack(self._peaks))
        object.__setattr__(self, "_maxima", [None, None])

    @property
    def peak_array(self) -> np.ndarray:
        """Largest |q'|, |q''|, |q'''| per joint over the zone, shape (3, n)."""
        return self._peak_array

    @property
    def absolute(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """|q'|, |q''|, |q'''| at the grid, each shape (G, n)."""
        return self._abs

    def part(self, first: int, stop: int) -> ZoneDemand:
        """The grid points ``first … stop - 1`` (their magnitudes: views of this zone's)."""
        rows = slice(first, stop)
        q1, q2, q3 = self._abs
        magnitudes = (q1[rows], q2[rows], q3[rows])
        return ZoneDemand(self.s[rows], self.d1[rows], self.d2[rows], self.d3[rows], magnitudes)

    def peaks(
        self, s_from: float | None = None, s_to: float | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Largest |q'|, |q''|, |q'''| per joint over the zone, or over [s_from, s_to].

        The stretch is widened by one grid point on each side (a peak between two grid
        points shows at the nearer one).
        """
        if s_from is None or s_to is None or len(self.s) < 2:
            return self._peaks
        rows = self._rows(s_from, s_to)
        if rows.start == 0:  # a stretch from the zone start: running maxima
            from_start: tuple[np.ndarray, np.ndarray, np.ndarray] = self.running_maxima(0)[
                rows.stop - 1
            ]
            return from_start
        if rows.stop == len(self.s):  # a stretch to the zone end
            to_end: tuple[np.ndarray, np.ndarray, np.ndarray] = self.running_maxima(1)[rows.start]
            return to_end
        q1, q2, q3 = self._abs
        return q1[rows].max(axis=0), q2[rows].max(axis=0), q3[rows].max(axis=0)

    def stretch_peaks(self, distance: np.ndarray, at_start: bool) -> np.ndarray:
        """Largest |q'|, |q''|, |q'''| over stretches of the zone's grid, shape (V, 3, n).

        Each stretch starts at the grid's first point (``at_start``) or ends at its last,
        and is ``distance`` (V,) metres long (widened by one grid point, as :meth:`peaks`).
        """
        if at_start:
            stop = np.searchsorted(self.s, self.s[0] + distance, side="left") + 2
            peaks: np.ndarray = self.running_maxima(0)[np.clip(stop, 1, len(self.s)) - 1]
            return peaks
        first = np.searchsorted(self.s, self.s[-1] - distance, side="right") - 2
        peaks = self.running_maxima(1)[np.clip(first, 0, len(self.s) - 1)]
        return peaks

    def quick_distances(
        self,
        v_from: np.ndarray,
        v_to: np.ndarray,
        rise: bool,
        length: float,
        a_limit: np.ndarray,
        j_limit: np.ndarray,
    ) -> np.ndarray:
        """Distances of speed changes under bounds valid over the stretch each covers, m.

        First the bounds over the whole zone at the top speed
        (:func:`uniform_change_bounds_many` on :meth:`peaks`, :func:`change_distances`);
        where that change fits the zone, the larger bounds over the shorter stretch it
        covers (:meth:`stretch_peaks`). Compiled:
        :func:`trackplan.timing._kernels.quick_distances`.

        Parameters
        ----------
        v_from, v_to
            Speeds before and after, shape (V,), m/s; all rises (``rise``) or all falls.
        rise
            True when the changes start at the zone start, False when they end at its end.
        length
            The zone's length, m.
        a_limit, j_limit
            Share of the joint acceleration and jerk limits planned against, shape (n,).

        Returns
        -------
        numpy.ndarray
            Shape (V,), m (inf where the joints leave no room).
        """
        return _kernels.quick_distances(
            self.s,
            self._peak_array,
            self.running_maxima(0 if rise else 1),
            v_from,
            v_to,
            rise,
            length,
            a_limit,
            j_limit,
        )

    def running_maxima(self, backward: int) -> np.ndarray:
        """Running maxima of |q'|, |q''|, |q'''| from the zone start (0) or from its end (1),
        shape (G, 3, n): row k covers rows 0 … k, or k … G - 1."""
        if self._maxima[backward] is None:
            stacked = np.stack(self._abs, axis=1)  # (G, 3, n)
            if backward:
                running = np.maximum.accumulate(stacked[::-1], axis=0)[::-1]
            else:
                running = np.maximum.accumulate(stacked, axis=0)
            self._maxima[backward] = running
        return self._maxima[backward]  # type: ignore[return-value]

    def _rows(self, s_from: float, s_to: float) -> slice:
        """Grid rows covering [s_from, s_to] plus one neighbour on each side."""
        first = max(int(np.searchsorted(self.s, s_from, side="right")) - 2, 0)
        stop = min(int(np.searchsorted(self.s, s_to, side="left")) + 2, len(self.s))
        return slice(first, max(stop, first + 1))

    def local_caps(self, robot: Robot | Machine, share: float) -> np.ndarray:
        """Highest constant speed the joint limits allow at each grid point, shape (G,), m/s.

        Per point the least of ``share · v_max / |q'|``, ``√(share · a_max / |q''|)`` and
        ``∛(share · j_max / |q'''|)`` over the joints (+inf where a demand is 0): one
        compiled pass (:func:`trackplan.timing._kernels_samples.local_caps`).
        """
        q1, q2, q3 = self._abs
        rooms = np.stack([share * robot.v_max, share * robot.a_max, share * robot.j_max])
        return _kernels_samples.local_caps(q1, q2, q3, rooms)


def cruise_cap(
    robot: Robot | Machine, peaks: tuple[np.ndarray, np.ndarray, np.ndarray], share: float
) -> tuple[float, str]:
    """Highest constant path speed the joint limits allow given peak demands, and what binds.

    Parameters
    ----------
    robot
        Joint limits, each shape (n,).
    peaks
        Largest |q'|, |q''|, |q'''| per joint, each shape (n,).
    share
        Share of each limit planned against.

    Returns
    -------
    tuple of (float, str)
        The speed, m/s, and e.g. ``"joint 3 jerk"``.
    """
    # a handful of joints: Python floats, the same IEEE operations as numpy's (math.sqrt
    # and math.cbrt are libm's, as np.sqrt and np.cbrt), without numpy's per-call cost
    best, reason = math.inf, ""
    for kind, limit, demand, root in (
        ("velocity", robot.v_max, peaks[0], None),
        ("acceleration", robot.a_max, peaks[1], math.sqrt),
        ("jerk", robot.j_max, peaks[2], math.cbrt),
    ):
        room = (share * np.asarray(limit, dtype=float)).tolist()
        values = [
            r / d if d > 0 else math.inf
            for r, d in zip(room, np.asarray(demand, dtype=float).tolist(), strict=True)
        ]
        if root is not None:
            values = [root(v) for v in values]
        j = min(range(len(values)), key=values.__getitem__)  # the first least, as argmin
        if values[j] < best:
            best, reason = values[j], f"joint {j + 1} {kind}"
    return best, reason


def uniform_change_bounds(
    robot: Robot | Machine,
    peaks: tuple[np.ndarray, np.ndarray, np.ndarray],
    top_speed: float,
    share: float,
) -> tuple[float, float]:
    """Path acceleration and jerk bounds valid wherever the demand stays below ``peaks``.

    From ``|q'| |s̈| + |q''| v² ≤ q̈max`` and ``|q'| |s⃛| + 3 |q''| v |s̈| + |q'''| v³ ≤ q⃛max``
    at the top speed, with the acceleration lowered where needed to leave half the jerk
    room to ``s⃛``. Conservative: the zone-wide fallback of :func:`speed_change`.

    Returns
    -------
    tuple of float
        ``(accel, jerk)``, m/s² and m/s³ (≤ 0 when the top speed leaves no room).
    """
    q1, q2, q3 = (np.asarray(p, dtype=float) for p in peaks)
    return _kernels.change_bounds(
        q1, q2, q3, float(top_speed), share * robot.a_max, share * robot.j_max
    )


def uniform_change_bounds_many(
    robot: Robot | Machine,
    peaks: tuple[np.ndarray, np.ndarray, np.ndarray] | np.ndarray,
    top_speed: np.ndarray,
    share: float,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`uniform_change_bounds` for many top speeds at once.

    Parameters
    ----------
    peaks
        Largest |q'|, |q''|, |q'''| per joint: three arrays of shape (n,) or (V, n)
        (a tuple or an array (3, n)), or one array of shape (V, 3, n).
    top_speed
        Shape (V,), m/s.

    Returns
    -------
    tuple of numpy.ndarray
        ``(accel, jerk)``, each shape (V,).
    """
    if isinstance(peaks, np.ndarray) and peaks.ndim == 3:
        peaks = peaks.swapaxes(0, 1)  # (3, V, n)
    q1, q2, q3 = (np.asarray(p) for p in peaks)
    top = np.asarray(top_speed, dtype=float)[:, None]
    accel_room = share * robot.a_max - q2 * top**2
    jerk_room = share * robot.j_max - q3 * top**3
    coupling = 3.0 * q2 * top
    accel = np.minimum(
        safe_ratio(accel_room, q1).min(axis=-1), safe_ratio(0.5 * jerk_room, coupling).min(axis=-1)
    )
    accel = np.minimum(accel, MAX_PATH_ACCELERATION)
    jerk = safe_ratio(jerk_room - coupling * accel[:, None], q1).min(axis=-1)
    return accel, np.minimum(jerk, MAX_PATH_JERK)


def change_distances(
    v_from: np.ndarray, v_to: np.ndarray, accel: np.ndarray, jerk: np.ndarray
) -> np.ndarray:
    """:func:`~trackplan.timing.profile.speed_change_distance` for arrays, m (inf where a
    bound is not positive, 0 where the speeds are equal)."""
    delta = np.abs(v_to - v_from)
    ok = (accel > 0.0) & (jerk > 0.0)
    a = np.where(ok, accel, 1.0)
    j = np.where(ok, jerk, 1.0)
    time = np.where(delta * j >= a * a, delta / a + a / j, 2.0 * np.sqrt(delta / j))
    distance = np.where(ok, 0.5 * (v_from + v_to) * time, np.inf)
    return np.where(delta == 0.0, 0.0, distance)


@dataclass(frozen=True)
class SpeedChange:
    """A jerk-limited speed change and the bounds it runs at.

    Attributes
    ----------
    distance
        Path length it covers, m (inf when the joint limits leave no room for it).
    accel, jerk
        Bounds on |s̈| (m/s²) and |s⃛| (m/s³) of its trapezoidal acceleration pulse.
    """

    distance: float
    accel: float
    jerk: float


def speed_change(
    robot: Robot | Machine,
    demand: ZoneDemand,
    s_start: float,
    s_end: float,
    v_from: float,
    v_to: float,
    at_start: bool,
    share: float,
    start: SpeedChange | None = None,
    *,
    quick_start: bool = False,
) -> SpeedChange:
    """Fastest jerk-limited speed change inside a zone, bounded by the joints along its stretch.

    The change starts at ``s_start`` (``at_start``) or ends at ``s_end``. It is a
    trapezoidal acceleration pulse (:func:`~trackplan.timing.profile.speed_change_phases`)
    with bounds ``accel`` and ``jerk``. The bounds valid over the whole zone at the top
    speed (:func:`uniform_change_bounds`) are always safe; larger ones are tried on a
    grid of multiples (:data:`BOUND_FACTORS` on each axis), each checked where it actually
    runs: at points along its own stretch, with its own speed, acceleration and jerk there,

        |q' a + q'' v²| ≤ q̈max,    |q' j + 3 q'' v a + q''' v³| ≤ q⃛max,

    using the signed joint-path derivatives interpolated from the zone's grid. The
    shortest change that passes wins; a second, finer grid around it refines it.

    Parameters
    ----------
    robot
        Joint limits, each shape (n,).
    demand
        The zone's joint-path derivatives (its grid may reach one point beyond the zone).
    s_start, s_end
        The zone, m.
    v_from, v_to
        Speeds before and after, m/s.
    at_start
        True when the change starts at the zone start, False when it ends at the zone end.
    share
        Share of each limit planned against.
    start
        A change known to meet the limits (bounds valid over its own stretch): the
        search starts from it when it is shorter than the zone-wide one.
    quick_start
        Start instead from the quick change: the zone-wide bounds raised to those over the
        stretch that change covers, where it fits the zone (a rise from ``s_start``, a fall
        to ``s_end``; :func:`trackplan.timing._kernels.quick_change`).

    Compiled: :func:`trackplan.timing._kernels.change_search`.

    Returns
    -------
    SpeedChange
        Its distance and bounds.
    """
    known = (np.inf, 0.0, 0.0) if start is None else (start.distance, start.accel, start.jerk)
    distance, accel, jerk = _kernels.change_search(
        demand.s,
        demand.d1,
        demand.d2,
        demand.d3,
        demand.peak_array,
        float(s_start),
        float(s_end),
        float(v_from),
        float(v_to),
        bool(at_start),
        share * robot.a_max,
        share * robot.j_max,
        (float(known[0]), float(known[1]), float(known[2])),
        demand.running_maxima(0),
        demand.running_maxima(1),
        bool(quick_start),
        BOUND_FACTORS,
        FINE_FACTORS,
        _PHASE_SHARES,
    )
    return SpeedChange(distance, accel, jerk)


BOUND_FACTORS = np.geomspace(1.0, 8.0, 6)
"""Multiples of the zone-wide bounds tried first for a speed change (each axis)."""
FINE_FACTORS = np.geomspace(0.85, 1.15, 3)
"""Multiples of the best first-round bounds tried second (each axis)."""
PHASE_POINTS = 6
"""Check points in each of a change's constant-jerk phases (both ends included)."""
_PHASE_SHARES = np.linspace(0.0, 1.0, PHASE_POINTS)


def _changes_within_limits(
    robot: Robot | Machine,
    demand: ZoneDemand,
    s_start: float,
    s_end: float,
    v_from: float,
    v_to: float,
    at_start: bool,
    share: float,
    accel: np.ndarray,
    jerk: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Which candidate speed changes meet the joint limits along their own stretch.

    Each is checked at :data:`PHASE_POINTS` points of each of its constant-jerk phases,
    with the signed joint-path derivatives interpolated linearly from the zone's grid
    (compiled: :func:`trackplan.timing._kernels.changes_within_limits`).

    Parameters
    ----------
    accel, jerk
        Candidate bounds, shape (K,), m/s² and m/s³.

    Returns
    -------
    ok : numpy.ndarray
        Shape (K,), bool.
    distance : numpy.ndarray
        Path length of each change, shape (K,), m.
    """
    return _kernels.changes_within_limits(
        demand.s,
        demand.d1,
        demand.d2,
        demand.d3,
        s_start,
        s_end,
        v_from,
        v_to,
        at_start,
        share * robot.a_max,
        share * robot.j_max,
        np.ascontiguousarray(accel, dtype=float),
        np.ascontiguousarray(jerk, dtype=float),
        _PHASE_SHARES,
    )
