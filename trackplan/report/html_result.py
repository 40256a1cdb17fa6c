"""The report's result tables: key figures, margins, violations, slow-downs, references."""

from __future__ import annotations

import numpy as np

from trackplan.case import Case
from trackplan.planning.result import LIMIT_KINDS, SEAM, PlanResult
from trackplan.report.cycle import has_moves
from trackplan.report.html_markup import (
    Cell,
    esc,
    grid,
    key_values,
    margin_class,
    num,
    percent,
)
from trackplan.report.scene import JOINT_QUANTITIES, column_units
from trackplan.robots.machine import Machine


def verdict_badge(result: PlanResult) -> str:
    """The verdict (status) as a coloured badge."""
    css = "ok" if result.feasible else "bad"
    return f'<span class="verdict {css}">{esc(result.status.value)}</span>'


def figures_table(result: PlanResult, case: Case) -> str:
    """The key figures of a run: verdict, placement, J, duration, speeds, errors."""
    check = result.check
    task = case.task
    ideal = result.path_length / task.rated_speed if task.rated_speed > 0 else float("nan")
    x = result.placement
    ideal_row = (
        "L / v_r (no ramps, no corners)",
        f"{num(ideal, unit='s')}; duration is "
        f"{num(result.duration / ideal if ideal else float('nan'))} × that",
    )
    if has_moves(result, case):  # each seam at its own rated speed, against the welding time
        ideal = sum(
            seam.plan.path_length / case.seams[seam.index].task.rated_speed for seam in result.seams
        )
        ideal_row = (
            "Σ L / v_r over the seams",
            f"{num(ideal, unit='s')}; welding takes "
            f"{num(result.seam_time / ideal if ideal else float('nan'))} × that",
        )
    rows = [
        ("verdict", verdict_badge(result)),
        ("message", esc(result.message)),
        (
            "placement X",
            f"({num(x[0])}, {num(x[1])}, {num(x[2])}) m, "
            f"rpy ({num(x[3])}, {num(x[4])}, {num(x[5])}) rad",
        ),
        ("objective J (Eq. 8)", num(result.objective, 6)),
        ("duration", num(result.duration, unit="s")),
        ("path length", num(result.path_length, unit="m")),
        ideal_row,
        _rated_speed_row(result, task.rated_speed),
        ("min corner speed", num(result.min_corner_speed, scale=1e3, unit="mm/s")),
        (
            "max tracking error",
            f"{num(check.max_tracking_error, scale=1e3, unit='mm')} "
            f"(ρ = {num(task.tolerance, scale=1e3, unit='mm')})",
        ),
        (
            "max orientation error",
            f"{num(check.max_orientation_error, unit='rad')} "
            f"({num(np.degrees(check.max_orientation_error))}°)",
        ),
        (
            "worst margin",
            percent(check.worst_margin()) if check.joint_margins or check.task_margins else "–",
        ),
        *_energy_rows(result),
        *downhand_rows(result, case),
        *_weave_rows(result),
        ("time law, IK branch", f"{esc(result.timing)}, branch {result.branch}"),
        (
            "samples",
            f"{result.trajectory.n_samples} at "
            f"Ts = {num(result.trajectory.sample_time, scale=1e3, unit='ms')}",
        ),
    ]
    return key_values(rows)


def _rated_speed_row(result: PlanResult, rated_speed: float) -> tuple[str, str]:
    """The share of the path run at the rated speed, or the top speed when that share
    would read 0.0 % (a curve cruising just below the rated speed; ``docs/results.md``)."""
    share = percent(result.rated_speed_fraction)
    if share != "0.0 %":
        return "rated speed fraction", share
    top = float(np.max(result.trajectory.speed, initial=0.0))
    of_rated = f" ({percent(top / rated_speed)} of v_r)" if rated_speed > 0 else ""
    return "top speed", num(top, scale=1e3, unit="mm/s") + of_rated


def _weave_rows(result: PlanResult) -> list[tuple[str, str]]:
    """The weave reached (``docs/positioner.md#weaving``), when the task weaves."""
    weave = result.weave
    if weave is None:
        return []
    reached = (
        f"{num(weave.amplitude, scale=1e3, unit='mm')} at {num(weave.frequency, unit='Hz')} "
        f"({esc(weave.pattern)}, plane {esc(weave.plane)})"
    )
    return [("weave reached", reached)]


def _energy_rows(result: PlanResult) -> list[tuple[str, str]]:
    """Energy figures of a robot with dynamics (``docs/dynamics.md``), else none."""
    energy = result.energy
    if energy is None:
        return []
    return [
        ("mechanical energy", num(energy.mechanical_energy, unit="J")),
        ("copper loss", f"{num(energy.copper_loss)} {esc(energy.copper_loss_unit)}"),
        (
            "peak torque ratio",
            f"{num(energy.peak_torque_ratio)} (joint {energy.peak_torque_joint})",
        ),
    ]


def external_axes_table(result: PlanResult, case: Case) -> str:
    """The external axes of the case's machine (track, positioner): name, kind, the range
    the trajectory uses against the axis's range, and the peak speed against its limit;
    empty without external axes."""
    machine = case.machine
    if not isinstance(machine, Machine) or machine.n_external == 0:
        return ""
    trajectory = result.trajectory
    units = column_units(machine, "position")
    speed_units = column_units(machine, "velocity")
    rows: list[list[Cell]] = []
    for j in range(machine.n_arm, machine.n_dof):
        unit, speed_unit = units[j], speed_units[j]
        if trajectory.n_samples and trajectory.q.shape[1] > j:
            low, high = np.min(trajectory.q[:, j]), np.max(trajectory.q[:, j])
            used = f"[{num(low)}, {num(high)}] {unit}"
            peak = f"{num(np.max(np.abs(trajectory.qd[:, j])))} {speed_unit}"
        else:
            used = peak = "–"
        rows.append(
            [
                esc(machine.joint_names[j]),
                esc(machine.kinds[j]),
                used,
                f"[{num(machine.q_min[j])}, {num(machine.q_max[j])}] {unit}",
                peak,
                f"{num(machine.v_max[j])} {speed_unit}",
            ]
        )
    header = ["axis", "kind", "range used", "range", "peak velocity", "velocity limit"]
    return '<h3 id="external-axes">External axes</h3>' + grid(header, rows)


def downhand_rows(result: PlanResult, case: Case) -> list[tuple[str, str]]:
    """The downhand figures of a result whose task has the rule (``result.check.downhand``:
    the largest slope of the travel direction to the horizontal and rotation of the weld
    normal from straight up, against the bounds, and the share of samples within both);
    none otherwise."""
    figures = result.check.downhand
    if figures is None:
        return []
    rows = []
    for label, value, bound in (
        ("largest downhand slope", figures.max_slope, figures.slope),
        ("largest downhand rotation", figures.max_rotation, figures.rotation),
    ):
        text = (
            f"{num(value, unit='rad')} ({num(np.degrees(value))}°, bound {num(np.degrees(bound))}°)"
        )
        rows.append((label, text))
    rows.append(("samples downhand", f"{num(100.0 * figures.share)} %"))
    return rows


def margins_table(result: PlanResult, case: Case) -> str:
    """The unused fraction of every joint limit per joint, and of the task bounds."""
    check = result.check
    machine = case.machine
    n, n_arm = machine.n_dof, case.robot.n_dof
    names = [f"joint {j + 1}" if j < n_arm else esc(machine.joint_names[j]) for j in range(n)]
    rows = []
    for kind in (*LIMIT_KINDS, "torque"):
        margins = check.joint_margins.get(kind)
        if margins is None:
            continue
        name, unit = JOINT_QUANTITIES[kind]
        if kind in LIMIT_KINDS:  # a track's column in m, m/s, …
            unit = ", ".join(dict.fromkeys(column_units(machine, kind)))
        cells: list[Cell] = [f"{name} [{unit}]"]
        for j in range(n):
            if j < len(margins):
                cells.append((percent(margins[j]), margin_class(margins[j])))
            else:
                cells.append("–")
        binding = check.binding.get(kind)
        if binding:
            j = binding[0] - 1
            where = names[j] if n_arm <= j < n else f"joint {binding[0]}"
            cells.append(f"{where} at t = {num(binding[1])} s")
        else:
            cells.append("–")
        rows.append(cells)
    joints = grid(["limit", *names, "closest to binding"], rows)
    tasks = grid(
        ["task bound", "margin"],
        [[esc(k), (percent(v), margin_class(v))] for k, v in check.task_margins.items()],
    )
    return (
        '<h3>Margins</h3><p class="muted">Unused fraction of each limit over all samples '
        "(1 − |x| / limit; negative = exceeded).</p>" + joints + tasks
    )


def violations_table(result: PlanResult, limit: int = 60) -> str:
    """The violation windows the checker reported, the first ``limit`` of them."""
    violations = result.check.violations
    if not violations:
        return "<h3>Violations</h3><p>None.</p>"
    rows: list[list[Cell]] = [
        [
            esc(v.limit),
            "–" if v.joint is None else str(v.joint),
            num(v.t_first, unit="s"),
            num(v.t_last, unit="s"),
            num(v.worst),
            num(v.bound),
            (esc(v.message), "text"),
        ]
        for v in violations[:limit]
    ]
    more = f"<p>… and {len(violations) - limit} more.</p>" if len(violations) > limit else ""
    header = ["limit", "joint", "first", "last", "worst", "bound", "message"]
    return f"<h3>Violations ({len(violations)})</h3>" + grid(header, rows) + more


def slowdowns_table(result: PlanResult) -> str:
    """The slow-downs below the rated speed, numbered as ``speed.png`` labels them."""
    if not result.slowdowns:
        return "<h3>Slow-downs</h3><p>None: every straight piece runs at the rated speed.</p>"
    seams = _slowdown_seams(result)
    rows: list[list[Cell]] = [
        [
            str(k + 1),  # the number speed.png labels it with
            *([(esc(seams[k]), "text")] if seams else []),
            num(s.s_start, unit="m"),
            num(s.s_end, unit="m"),
            num(s.speed, scale=1e3, unit="mm/s"),
            num(s.rated_speed, scale=1e3, unit="mm/s"),
            (esc(s.limit), "text"),
        ]
        for k, s in enumerate(result.slowdowns)
    ]
    header = ["#", *(["seam"] if seams else []), "from s", "to s", "speed", "rated", "forced by"]
    return "<h3>Slow-downs</h3>" + grid(header, rows)


def _slowdown_seams(result: PlanResult) -> list[str]:
    """The seam of each of ``result.slowdowns`` (every seam's in welding order, ``s`` along
    its own seam) when the plan has moves between seams, else none."""
    if not any(span.kind != SEAM for span in result.spans):
        return []
    names = [seam.name for seam in result.seams for _ in seam.plan.slowdowns]
    return names if len(names) == len(result.slowdowns) else []


def references_table(result: PlanResult) -> str:
    """The reference durations (toppra, TOPP3) against the run's, when computed."""
    if not result.references:
        return "<h3>Reference durations</h3><p>Not computed.</p>"
    rows = [
        [
            esc(name.removesuffix("_duration")),
            num(value, unit="s"),
            num(result.duration / value if value else float("nan")),
        ]
        for name, value in result.references.items()
    ]
    return "<h3>Reference durations</h3>" + grid(
        ["reference", "duration", "ours / reference"], rows
    )
