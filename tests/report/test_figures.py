"""The static plots: what each figure holds, not only that a file appears."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from trackplan.frames import placement_transform
from trackplan.planning.result import LIMIT_KINDS, Violation
from trackplan.report import (
    convergence_figure,
    joints_figure,
    path_figure,
    speed_figure,
    write_plots,
)
from trackplan.report.joints_plot import envelope
from trackplan.report.scene import JOINT_QUANTITIES, joint_bounds, joint_series, transform_points


def _by_gid(ax, gid):
    return [line for line in ax.lines if line.get_gid() == gid]


@pytest.fixture(scope="module")
def joints(corner, corner_result):
    return joints_figure(corner_result, corner)


def test_joints_grid_has_one_panel_per_joint_and_derivative(joints, corner):
    n = corner.robot.n_dof
    assert len(joints.axes) == len(LIMIT_KINDS) * n


def test_joints_every_panel_has_its_pair_of_limit_lines_and_one_series(
    joints, corner, corner_result
):
    n = corner.robot.n_dof
    grid = np.array(joints.axes).reshape(len(LIMIT_KINDS), n)
    for row, kind in enumerate(LIMIT_KINDS):
        lower, upper = joint_bounds(corner.robot, kind)
        values = joint_series(corner_result.trajectory, kind)
        for j in range(n):
            ax = grid[row, j]
            limits = _by_gid(ax, "limit")
            assert len(limits) == 2, (kind, j)
            drawn = sorted(float(line.get_ydata()[0]) for line in limits)
            assert drawn == pytest.approx([lower[j], upper[j]])
            assert all(line.get_linestyle() == "--" for line in limits)
            series = [line for line in ax.lines if line.get_label() == corner.robot.joint_names[j]]
            assert len(series) == 1
            np.testing.assert_array_equal(series[0].get_ydata(), values[:, j])


def test_joints_axis_labels_carry_units(joints, corner):
    n = corner.robot.n_dof
    grid = np.array(joints.axes).reshape(len(LIMIT_KINDS), n)
    for row, kind in enumerate(LIMIT_KINDS):
        assert f"[{JOINT_QUANTITIES[kind][1]}]" in grid[row, 0].get_ylabel()
    assert all(ax.get_xlabel() == "time [s]" for ax in grid[-1])


def test_joints_mark_the_planted_violation_and_nothing_else(joints, corner, corner_result):
    (violation,) = corner_result.check.violations
    assert (violation.limit, violation.joint) == ("jerk", 6)
    n = corner.robot.n_dof
    grid = np.array(joints.axes).reshape(len(LIMIT_KINDS), n)
    for row, kind in enumerate(LIMIT_KINDS):
        for j in range(n):
            ax = grid[row, j]
            markers = _by_gid(ax, "violation")
            windows = [p for p in ax.patches if p.get_gid() == "violation-window"]
            if (kind, j + 1) == (violation.limit, violation.joint):
                (marker,) = markers
                y = np.asarray(marker.get_ydata())
                assert y.size > 0 and np.all(np.abs(y) > corner.robot.j_max[j])
                assert np.max(np.abs(y)) == pytest.approx(abs(violation.worst))
                assert marker.get_color() == "red"
                assert len(windows) == 1
                x0 = windows[0].get_x()
                assert x0 <= violation.t_first <= x0 + windows[0].get_width()
            else:
                assert not markers and not windows, (kind, j)


def test_joints_tick_only_inside_each_panel(joints):
    # matplotlib makes a tick object for every location, drawn or not
    for ax in joints.axes:
        for ticks, (low, high) in (
            (ax.get_xticks(), ax.get_xlim()),
            (ax.get_yticks(), ax.get_ylim()),
        ):
            tolerance = 1e-9 * (high - low)
            assert len(ticks) >= 2
            assert np.all((ticks >= low - tolerance) & (ticks <= high + tolerance))


@pytest.fixture(scope="module")
def path(corner, corner_result):
    return path_figure(corner_result, corner)


def test_path_holds_both_paths_in_their_frames(path, corner_result):
    cell = path.axes[0]
    (before,) = _by_gid(cell, "path-before")
    (after,) = _by_gid(cell, "path-after")
    assert before.get_linestyle() == "--" and after.get_linestyle() == "-"
    tool = corner_result.trajectory.tool_position
    np.testing.assert_allclose(np.column_stack(after.get_data_3d()), tool)
    T_base_part = placement_transform(corner_result.placement)
    definition = np.column_stack(before.get_data_3d())
    np.testing.assert_allclose(transform_points(T_base_part, definition), tool, atol=1e-12)


def test_path_draws_the_reach_shell_and_frames(path, corner, corner_result):
    cell, close_up = path.axes
    shells = _by_gid(cell, "reach-shell")
    radii = []
    for line in shells:
        points = np.column_stack(line.get_data_3d()).astype(float)
        finite = points[np.all(np.isfinite(points), axis=1)]
        radius = np.linalg.norm(finite, axis=1)
        np.testing.assert_allclose(radius, radius[0])
        radii.append(radius[0])
    assert sorted(radii) == pytest.approx(sorted(corner.bounds.reach))
    assert len(_by_gid(cell, "base-frame")) == 3
    assert len(_by_gid(cell, "robot")) == 1
    assert len(_by_gid(close_up, "tool-frames")) == 3
    assert len(_by_gid(close_up, "violation")) == 1


def test_path_base_and_part_frames_differ_in_colour_and_legend(path):
    """The base and the part frame were both drawn in red, green and blue under one red
    legend swatch each: their colours now differ axis by axis, and so do their legend
    entries."""
    from matplotlib.colors import to_hex

    cell = path.axes[0]
    colours = {}
    for gid in ("base-frame", "part-frame"):
        lines = _by_gid(cell, gid)
        assert len(lines) == 3
        colours[gid] = [to_hex(line.get_color()) for line in lines]
    assert not set(colours["base-frame"]) & set(colours["part-frame"])
    (legend,) = path.legends
    entries = dict(
        zip([t.get_text() for t in legend.get_texts()], legend.legend_handles, strict=True)
    )
    base = [label for label in entries if label.startswith("base frame")]
    part = [label for label in entries if label.startswith("part frame")]
    assert len(base) == len(part) == 1
    base_swatch, part_swatch = entries[base[0]], entries[part[0]]
    assert to_hex(base_swatch.get_color()) != to_hex(part_swatch.get_color())
    assert base_swatch.get_linestyle() != part_swatch.get_linestyle()


def test_path_axes_have_equal_aspect(path):
    for ax in path.axes:
        widths = [np.ptp(ax.get_xlim()), np.ptp(ax.get_ylim()), np.ptp(ax.get_zlim())]
        np.testing.assert_allclose(widths, widths[0])
        assert ax.get_xlabel() == "x [m]" and ax.get_zlabel() == "z [m]"
        for ticks, (low, high) in zip(
            (ax.get_xticks(), ax.get_yticks(), ax.get_zticks()),
            (ax.get_xlim(), ax.get_ylim(), ax.get_zlim()),
            strict=True,
        ):
            tolerance = 1e-9 * (high - low)
            assert len(ticks) >= 2
            assert np.all((ticks >= low - tolerance) & (ticks <= high + tolerance))


def test_speed_figure_bounds_and_series(corner, corner_result):
    figure = speed_figure(corner_result, corner)
    ax_speed, ax_error = figure.axes
    (speed,) = _by_gid(ax_speed, "speed")
    np.testing.assert_allclose(speed.get_ydata(), 1e3 * corner_result.trajectory.speed)
    (rated,) = _by_gid(ax_speed, "rated-speed")
    (corner_cap,) = _by_gid(ax_speed, "corner-speed")
    assert rated.get_ydata()[0] == pytest.approx(1e3 * corner.task.rated_speed)
    assert corner_cap.get_ydata()[0] == pytest.approx(1e3 * corner.task.corner_speed)
    (error,) = _by_gid(ax_error, "tracking-error")
    assert np.max(error.get_ydata()) == pytest.approx(1e3 * corner_result.check.max_tracking_error)
    (tolerance,) = _by_gid(ax_error, "tolerance")
    assert tolerance.get_ydata()[0] == pytest.approx(1e3 * corner.task.tolerance)
    assert ax_speed.get_ylabel() == "tool speed [mm/s]"
    assert ax_error.get_ylabel() == "tracking error [mm]"
    assert ax_error.get_xlabel() == "time [s]"
    assert len([p for p in ax_speed.patches if p.get_gid() == "slowdown"]) == 1
    assert not _by_gid(ax_speed, "violation") and not _by_gid(ax_error, "violation")


def _overlapping_texts(figure):
    """Pairs of the texts a plot adds (axes texts and annotations, legend entries) whose
    bounding boxes intersect."""
    renderer = figure.canvas.get_renderer()
    figure.canvas.draw()
    texts = [text for ax in figure.axes for text in ax.texts]
    legends = [ax.get_legend() for ax in figure.axes] + list(figure.legends)
    texts += [text for legend in legends if legend is not None for text in legend.get_texts()]
    texts = [text for text in texts if text.get_visible() and text.get_text().strip()]
    boxes = [text.get_window_extent(renderer) for text in texts]
    return [
        (texts[i].get_text(), texts[j].get_text())
        for i, j in itertools.combinations(range(len(texts)), 2)
        if boxes[i].overlaps(boxes[j])
    ]


def test_speed_figure_slowdown_labels_do_not_overlap(corner, corner_result):
    """Many slow-downs close together: every one is numbered on the plot, the numbers of
    neighbours too close to label apart share one label ("3–5"), each reason is given
    once in the legend with the numbers it applies to, and no two texts overlap (the
    reasons were written in full at every slow-down, on top of each other)."""
    from trackplan.timing import SlowDown

    length = float(corner_result.trajectory.s[-1])
    rated = corner.task.rated_speed
    starts = np.concatenate([np.linspace(0.30, 0.33, 6), np.linspace(0.6, 0.9, 8)]) * length
    reasons = [
        "joint 4 velocity",
        "too short to reach the rated speed under the joint acceleration and jerk limits",
    ]
    slowdowns = tuple(
        SlowDown(s0, s0 + 0.002, 0.7 * rated, rated, reasons[k % 2]) for k, s0 in enumerate(starts)
    )
    figure = speed_figure(dataclasses.replace(corner_result, slowdowns=slowdowns), corner)
    assert _overlapping_texts(figure) == []
    ax_speed = figure.axes[0]
    labels = [t.get_text() for t in ax_speed.texts if t.get_gid() == "slowdown-label"]
    numbered = []
    for label in labels:
        first, _, last = label.partition("–")
        numbered += list(range(int(first), int(last or first) + 1))
    assert numbered == list(range(1, len(slowdowns) + 1))
    assert len(labels) < len(slowdowns)  # the six within 3 % of the path share labels
    x_low, x_high = ax_speed.get_window_extent().x0, ax_speed.get_window_extent().x1
    renderer = figure.canvas.get_renderer()
    for text in ax_speed.texts:
        box = text.get_window_extent(renderer)
        assert x_low - 1 <= box.x0 and box.x1 <= x_high + 1
    figure_box = figure.bbox
    for text in ax_speed.get_legend().get_texts():
        box = text.get_window_extent(renderer)
        assert box.x1 <= figure_box.x1 and box.y0 >= figure_box.y0, text.get_text()
    legend = " ".join(t.get_text() for t in ax_speed.get_legend().get_texts())
    legend = " ".join(legend.split())
    for reason in reasons:
        assert legend.count(reason) == 1


def test_speed_figure_marks_a_reported_speed_violation(corner, corner_result):
    t = corner_result.trajectory.t
    k = int(np.argmax(corner_result.trajectory.speed))
    overspeed = Violation(
        limit="speed",
        joint=None,
        t_first=float(t[k - 2]),
        t_last=float(t[k + 2]),
        worst=0.16,
        bound=0.15,
        message="speed",
    )
    check = dataclasses.replace(corner_result.check, violations=(overspeed,))
    figure = speed_figure(dataclasses.replace(corner_result, check=check), corner)
    (marker,) = _by_gid(figure.axes[0], "violation")
    np.testing.assert_allclose(marker.get_xdata(), t[k - 2 : k + 3])


def test_convergence_one_series_per_method_and_panel(history):
    figure = convergence_figure(history)
    assert len(figure.axes) == 3
    for ax, key in zip(figure.axes, ("best", "mean", "feasible_share"), strict=True):
        lines = [line for line in ax.lines if line.get_gid() in history]
        assert sorted(line.get_gid() for line in lines) == sorted(history)
        for line in lines:
            table = history[line.get_gid()]
            np.testing.assert_array_equal(line.get_xdata(), table["evaluations"])
            scale = 100.0 if key == "feasible_share" else 1.0
            np.testing.assert_allclose(line.get_ydata(), scale * table[key])
    colors = {line.get_gid(): line.get_color() for line in figure.axes[0].lines}
    assert len(set(colors.values())) == len(history)
    for ax, key in zip(figure.axes[:2], ("best", "mean"), strict=True):
        values = np.concatenate([table[key] for table in history.values()])
        wide = values.max() >= 10 * values.min()  # a decade or more: log
        assert ax.get_yscale() == ("log" if wide else "linear")
    assert figure.axes[2].get_ylabel() == "feasible share [%]"


def test_convergence_rejects_an_incomplete_history(history):
    del history["ga"]["mean"]
    with pytest.raises(ValueError, match="'ga' lacks mean"):
        convergence_figure(history)


def test_write_plots_writes_png_files(tmp_path, corner, corner_result, history):
    written = write_plots(corner_result, corner, tmp_path / "run", history)
    assert [p.name for p in written] == ["joints.png", "path.png", "speed.png", "convergence.png"]
    for file in written:
        assert file.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plots_without_a_trajectory(tmp_path, corner, unreachable_result):
    joints = joints_figure(unreachable_result, corner)
    assert "no trajectory" in joints.get_suptitle()
    assert len(_by_gid(joints.axes[0], "limit")) == 2
    path = path_figure(unreachable_result, corner)
    assert len(_by_gid(path.axes[0], "path-after")) == 1
    assert not _by_gid(path.axes[0], "robot")
    written = write_plots(unreachable_result, corner, tmp_path)
    assert [p.name for p in written] == ["joints.png", "path.png", "speed.png"]


def test_joints_use_symlog_when_violations_dwarf_the_limits(corner, corner_result):
    wild = dataclasses.replace(corner_result.trajectory, qddd=1000 * corner_result.trajectory.qddd)
    figure = joints_figure(dataclasses.replace(corner_result, trajectory=wild), corner)
    grid = np.array(figure.axes).reshape(len(LIMIT_KINDS), corner.robot.n_dof)
    jerk = LIMIT_KINDS.index("jerk")
    assert {ax.get_yscale() for ax in grid[jerk]} == {"symlog"}
    assert {ax.get_yscale() for ax in grid[:jerk].ravel()} == {"linear"}
    assert all(len(_by_gid(ax, "limit")) == 2 for ax in grid[jerk])


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    n=st.integers(min_value=1, max_value=9000),
    n_points=st.integers(min_value=4, max_value=3000),
    seed=st.integers(min_value=0, max_value=2**32 - 1),
)
def test_envelope_keeps_the_extremes_of_every_stretch(n, n_points, seed):
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.1, 1.0, n))
    y = np.cumsum(rng.normal(size=n)) * rng.choice([1.0, 1e-9, 1e9])
    t_env, y_env = envelope(t, y, n_points)
    if n <= n_points:
        assert t_env is t and y_env is y
        return
    assert len(t_env) <= n_points
    assert np.all(np.diff(t_env) > 0)  # samples of the series, in time order
    np.testing.assert_array_equal(y_env, y[np.searchsorted(t, t_env)])
    assert y_env.max() == y.max() and y_env.min() == y.min()
    # every stretch between kept samples stays within what the envelope draws about it
    edges = np.linspace(0, n, n_points // 2 + 1).astype(int)
    for lo, hi in itertools.pairwise(edges):
        inside = (t_env >= t[lo]) & (t_env <= t[hi - 1])
        assert y[lo:hi].max() in y_env[inside] and y[lo:hi].min() in y_env[inside]


def test_convergence_minor_ticks_only_over_few_decades():
    evaluations = np.arange(1, 11) * 10.0
    wide = {"evaluations": evaluations, "generation": np.arange(1, 11)}
    wide |= {"feasible_share": np.linspace(0, 1, 10), "wall_time": evaluations / 100}
    wide |= {"best": np.geomspace(1e4, 1.0, 10), "mean": np.geomspace(1e6, 1.0, 10)}
    narrow = dict(wide, best=np.geomspace(50.0, 1.0, 10), mean=np.geomspace(80.0, 1.0, 10))
    for table, minor in ((wide, False), (narrow, True)):
        figure = convergence_figure({"ga": table})
        for ax in figure.axes[:2]:
            assert ax.get_yscale() == "log"
            low, high = ax.get_ylim()
            ticks = [v for v in ax.yaxis.get_minorticklocs() if low <= v <= high]
            assert bool(ticks) is minor


def _tick_labels(ax, low, high):
    """The (value, text) of every labelled y tick (major and minor) inside the view."""
    ax.figure.canvas.draw()
    ticks = []
    for locations, labels in (
        (ax.yaxis.get_majorticklocs(), ax.yaxis.get_majorticklabels()),
        (ax.yaxis.get_minorticklocs(), ax.yaxis.get_minorticklabels()),
    ):
        for value, label in zip(locations, labels, strict=False):
            if low <= value <= high and label.get_text():
                ticks.append((float(value), label.get_text()))
    return sorted(ticks)


@pytest.mark.parametrize(
    ("low", "high"),
    [(0.7, 0.79), (0.72, 0.78), (0.66449, 0.6646), (0.6645, 0.9), (0.8, 1.2), (0.3, 5.0)],
)
def test_convergence_fitness_ticks_are_distinct_and_readable(low, high):
    """Over a narrow range every labelled tick reads differently and says its own value
    (formerly every label of 0.70-0.79 read 7e−01)."""
    evaluations = np.arange(1, 31) * 100.0
    table = {"evaluations": evaluations, "generation": np.arange(1, 31)}
    table |= {"feasible_share": np.linspace(0, 1, 30), "wall_time": evaluations / 100}
    table |= {"best": np.geomspace(high, low, 30), "mean": np.geomspace(high, low, 30)}
    figure = convergence_figure({"multistart": table})
    for ax in figure.axes[:2]:
        ticks = _tick_labels(ax, *ax.get_ylim())
        assert len(ticks) >= 3, ticks
        texts = [text for _, text in ticks]
        assert len(set(texts)) == len(texts), ticks
        values = np.array([value for value, _ in ticks])
        step = np.min(np.diff(values))
        for value, text in ticks:
            # the label is the tick's value to within half the spacing of the ticks
            assert float(text.replace("−", "-")) == pytest.approx(value, abs=0.5 * step)
        assert ax.get_yscale() == ("linear" if high < 10 * low else "log")
