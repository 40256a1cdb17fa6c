"""Every figure the pages state outside ``console`` blocks, with the command that prints it.

``make docs`` rewrites them from fresh runs (``tests/docs/regenerate.py``);
``tests/docs/test_stated.py`` fails when one no longer agrees with what the code prints
(``figures.agree``: within one unit of the last digit the page prints). Measured timings
(CPU and wall seconds, rates) are measurements of one machine, stated as such with their
command, and are not listed here.
"""

from __future__ import annotations

import csv
import io
import json
import re
import textwrap
from pathlib import Path

from tests.docs.figures import Block, Done, Picture, Stated, Workspace, printed, summary_csv
from tests.docs.screenshots import VIEW_ID, Shot

# the commands, as written once so that figures from the same run share it
WALK_OPTIMIZE = "trackplan optimize cases/bracket-weld.yaml --out runs/bracket"
"""The README walk-through's search (also writes the report of the screenshots)."""
WALK_EXPORT = "trackplan export runs/bracket --format ros"
STUDY = "trackplan batch studies/robot-selection.yaml --out runs/robot-selection --no-report"
CORNER = "trackplan optimize cases/paper-corner.yaml --out runs/corner-travel --no-report"
CORNER_CELL = "trackplan optimize cases/paper-corner-cell.yaml --out runs/corner-cell --no-report"
TWO_FACES = "trackplan optimize cases/bracket-two-faces.yaml --out runs/two-faces --no-report"
TWO_FACES_PLAN = (
    "trackplan plan cases/bracket-two-faces.yaml --out runs/two-faces-example --no-report"
)
TWO_FACES_CHECK = "trackplan check cases/bracket-two-faces.yaml runs/two-faces-example"
PIPE_FILLET = "trackplan optimize cases/pipe-fillet.yaml --out runs/pipe-fillet --no-report"
PIPE_FILLET_PLAN = (
    "trackplan plan cases/pipe-fillet.yaml --out runs/pipe-fillet-example --no-report"
)
CIRCLE_FREE_PLAN = (
    "trackplan plan cases/paper-circle-seam-free.yaml --out runs/circle-seam-free --no-report"
)
CIRCLE_FREE = (
    "trackplan optimize cases/paper-circle-seam-free.yaml --budget 600 --restarts 1"
    " --out runs/circle-seam-free-search --no-report"
)
CIRCLE_PAPER = (
    "trackplan plan cases/paper-circle.yaml --placement 0.3922 0.4626 0.1924 -0.799 0.8431 "
    "-0.9053 --out runs/paper-circle-smooth --no-report"
)
"""As docs/paper.md runs it: the paper's constant tool at its example placement."""
CORNER_COPPER = (
    "trackplan optimize cases/paper-corner.yaml --objective copper --out runs/corner-copper"
    " --no-report"
)
CORNER_FRONT = (
    "trackplan optimize cases/paper-corner.yaml --pareto travel,copper --out runs/corner-front"
    " --no-report"
)
CORNER_PAPER = "trackplan plan cases/paper-corner.yaml --out runs/corner-paper --no-report"
"""The corner case at the paper's placement (the case's ``placement.example``)."""
PAYLOAD = "trackplan optimize cases/puma-payload.yaml --out runs/puma-payload-search --no-report"
BRACKET4 = "trackplan optimize cases/bracket-4-fillets.yaml --out runs/bracket4"
"""As the README and docs/seams.md run it."""
_LINE_X = "--placement -0.2230 0.1029 0.1829 0.0312 -0.4124 0.5020"
LINE_PAPER = (
    f"trackplan plan cases/paper-line.yaml --timing paper {_LINE_X} --out runs/paper-line-moved"
    " --no-report   # exit 3"
)
LINE_SMOOTH = (
    f"trackplan plan cases/paper-line.yaml {_LINE_X} --out runs/paper-line-smooth --no-report"
)
_CORNER_X = "--placement 0.0902 0.2090 0.2020 0.3263 0.3016 -0.2522"
CORNER_PAPER_TIMING = (
    f"trackplan plan cases/paper-corner.yaml --timing paper {_CORNER_X} --out runs/paper-corner"
    " --no-report   # exit 3"
)
CORNER_SMOOTH = (
    f"trackplan plan cases/paper-corner.yaml {_CORNER_X} --out runs/paper-corner-smooth --no-report"
)
_CIRCLE_X = "--placement 0.3922 0.4626 0.1924 -0.799 0.8431 -0.9053"
CIRCLE_PAPER_TIMING = (
    f"trackplan plan cases/paper-circle.yaml --timing paper {_CIRCLE_X} --out runs/paper-circle"
    " --no-report   # exit 3"
)
"""docs/paper.md's console commands, as written there (their runs are shared)."""
SEAM_WELD = "trackplan optimize cases/seam-weld-{}.yaml --out runs/seam-weld-{} --no-report"


def ros_points(_search: Done, export: Done) -> tuple[str, ...]:
    """The first two points of the walk-through's ROS message as docs/results.md shows them:
    positions to 4 decimals, the second point's velocities and accelerations to 4
    significant digits."""
    import numpy as np
    import yaml

    message = yaml.safe_load((export.cwd / "runs/bracket/trajectory.ros.yaml").read_text())
    first, second = message["points"][:2]

    def digits4(value: float) -> str:
        return np.format_float_positional(value, precision=4, unique=False, fractional=False)

    return (
        *(f"{q:.4f}" for q in first["positions"]),
        *(f"{q:.4f}" for q in second["positions"]),
        *(f"{v:.3e}" for v in second["velocities"]),
        *(digits4(a) for a in second["accelerations"]),
    )


def worst_gusset(done: Done) -> tuple[str, ...]:
    """The worst tracking error of the shipped bracket's seams, which docs/seams.md places at
    the gusset."""
    errors = {
        name: float(err)
        for name, err in re.findall(
            r"^  ([\w-]+): \S+ s, max tracking error (\S+) mm", done.stdout, re.M
        )
    }
    worst = max(errors, key=errors.__getitem__)
    if worst != "gusset":
        raise LookupError(
            f"docs/seams.md: the worst tracking error is now on {worst}: edit the page"
        )
    return (f"{errors[worst]:.2f}",)


def energy_row(done: Done) -> tuple[str, ...]:
    """X, J, duration, copper loss, mechanical energy and peak torque ratio of a run, as
    docs/dynamics.md's table prints them."""
    result = _json(done)
    return (
        *placement(done, 3),
        f"{result['objective']:.3f}",
        f"{result['duration']:.2f}",
        f"{result['copper_loss']:.2f}",
        f"{result['mechanical_energy']:.1f}",
        f"{result['peak_torque_ratio']:.3f}",
    )


def energy_ratios(travel: Done, copper: Done, paper: Done) -> tuple[str, ...]:
    """docs/dynamics.md's reading of its table: the travel-optimal placement's extra copper
    loss (%) and mechanical work (times) over the copper-optimal one, its joint travel saved
    (%), and the paper placement's extra copper loss and mechanical work."""
    t, c, p = _json(travel), _json(copper), _json(paper)
    return (
        f"{(t['copper_loss'] / c['copper_loss'] - 1) * 100:.0f}",
        f"{t['mechanical_energy'] / c['mechanical_energy']:.1f}",
        f"{(1 - t['objective'] / c['objective']) * 100:.0f}",
        f"{(p['copper_loss'] / c['copper_loss'] - 1) * 100:.0f}",
        f"{p['mechanical_energy'] / c['mechanical_energy']:.1f}",
    )


def corner_map(workspace: Workspace) -> Path:
    """docs/cell-map.png: the cell case's placement map at the height and orientation of the
    unconstrained optimum (as docs/cell.md's `trackplan map` command)."""
    _, _, z, roll, pitch, yaw = placement(workspace.ok(CORNER))
    done = workspace.ok(
        f"trackplan map cases/paper-corner-cell.yaml --rpy {roll} {pitch} {yaw} --z {z} "
        "--out runs/corner-cell-map"
    )
    return done.out() / "map.png"


PICTURES: tuple[Picture, ...] = (Picture("cell-map.png", corner_map),)

_REPORT = "runs/bracket/report.html"
SHOTS: tuple[Shot, ...] = (
    Shot("walkthrough-report-top.png", WALK_OPTIMIZE, _REPORT, None, VIEW_ID),
    Shot("walkthrough-report-view.png", WALK_OPTIMIZE, _REPORT, "#view", VIEW_ID, slide=True),
    Shot(
        "studies-matrix.png",
        STUDY,
        "runs/robot-selection/summary.html",
        "#feasibility-matrix",
        "feasibility-matrix",
    ),
)
"""The screenshots the docs show, of the pages the commands write."""


def _json(done: Done) -> dict:  # type: ignore[type-arg]
    return json.loads((done.out() / "result.json").read_text(encoding="utf-8"))


def placement(done: Done, decimals: int = 4) -> tuple[str, ...]:
    """x, y, z, roll, pitch, yaw of the run's placement, as the pages print them."""
    x = _json(done)["placement"]
    return tuple(f"{x[k]:.{decimals}f}" for k in ("x", "y", "z", "roll", "pitch", "yaw"))


J_DURATION = r"J = (\S+)  duration = (\S+) s"


def j_duration(done: Done) -> tuple[str, ...]:
    """J and the duration as the run's summary line prints them."""
    return printed(J_DURATION)(done)


def durations_then_js(paper: Done, smooth: Done) -> tuple[str, ...]:
    """The two runs' durations, then their J, as paper.md's comparison tables order them."""
    (j_paper, t_paper), (j_smooth, t_smooth) = j_duration(paper), j_duration(smooth)
    return t_paper, t_smooth, j_paper, j_smooth


STUDY_ARMS = (
    ("kuka_kr6_r700_sixx", "KR6 R700 sixx"),
    ("abb_irb1600", "IRB 1600"),
    ("ur10e", "UR10e"),
)


def study_table(done: Done) -> str:
    """The README's table of the robot-selection study: J per part and arm, the arm with the
    least J and its cycle time."""
    rows = summary_csv(done)
    feasible = [row for row in rows if row["status"] == "feasible"]
    lines = [
        f"It writes a run folder per job, `summary.csv` and `summary.html` ({len(rows)} jobs, "
        + ("all feasible" if len(feasible) == len(rows) else f"{len(feasible)} feasible")
        + "):",
        "",
        "| part | " + " | ".join(f"{name} J" for _, name in STUDY_ARMS) + " | best robot"
        " | cycle time s |",
        "| --- | " + " | ".join("---:" for _ in STUDY_ARMS) + " | --- | ---: |",
    ]
    for part in sorted({row["case"] for row in rows}):
        mine = {row["robot"]: row for row in feasible if row["case"] == part}
        cells = [f"{float(mine[key]['J']):.4f}" if key in mine else "–" for key, _ in STUDY_ARMS]
        best = min(mine.values(), key=lambda row: float(row["J"]), default=None)
        cycle = "–" if best is None else f"{float(best['cycle_time_s']):.2f}"
        tail = f"{'none' if best is None else best['robot']} | {cycle}"
        lines.append(f"| {part} | " + " | ".join(cells) + f" | {tail} |")
    return "\n".join(lines) + "\n"


def best_per_part(done: Done) -> str:
    """docs/studies.md's table of the arm with the least J per part."""
    rows = summary_csv(done)
    lines = [
        "| part | best robot | J rad | cycle time s | feasible robots |",
        "| --- | --- | ---: | ---: | ---: |",
    ]
    for part in sorted({row["case"] for row in rows}):
        mine = [row for row in rows if row["case"] == part]
        feasible = [row for row in mine if row["status"] == "feasible"]
        best = min(feasible, key=lambda row: float(row["J"]), default=None)
        figures = (
            "none | – | –"
            if best is None
            else f"{best['robot']} | {float(best['J']):.4f} | {float(best['cycle_time_s']):.2f}"
        )
        lines.append(f"| {part} | {figures} | {len(feasible)}/{len(mine)} |")
    return "\n".join(lines) + "\n"


def j_per_arm(done: Done) -> str:
    """docs/studies.md's table of J per part and arm."""
    table = study_table(done).splitlines()[2:]
    rows = [" | ".join(line.split(" | ")[: 1 + len(STUDY_ARMS)]) + " |" for line in table]
    return "\n".join(row.replace(" J |", " |") for row in rows) + "\n"


def energy_front(done: Done) -> str:
    """docs/dynamics.md's paragraph on the travel–copper front: its non-dominated points as
    planned, and the screened points that planning dominated."""
    evaluations = printed(r"\((\d+) evaluations\)")(done)[0]
    rows = list(csv.DictReader(io.StringIO((done.out() / "pareto.csv").read_text("utf-8"))))

    def point(row: dict[str, str]) -> str:
        return f"({float(row['travel']):.3f}, {float(row['copper']):.2f})"

    feasible = [row for row in rows if row["feasible"] == "True"]
    front = sorted(
        (r for r in feasible if r["nondominated"] == "True"), key=lambda r: float(r["travel"])
    )
    dominated = sorted(
        (r for r in feasible if r["nondominated"] != "True"), key=lambda r: float(r["travel"])
    )
    text = (
        f"The front between the two objectives (NSGA-II, population 30 × 40 generations = "
        f"{evaluations} evaluations, seed 0; every point planned and checked, "
        + (
            "all feasible"
            if len(feasible) == len(rows)
            else f"{len(feasible)} of {len(rows)} feasible"
        )
        + "; `travel, copper` as planned, non-dominated): "
        + ", ".join(point(row) for row in front)
    )
    if dominated:
        one = len(dominated) == 1
        shown = ", ".join(point(row) for row in dominated[:-1])
        shown = f"{shown} and {point(dominated[-1])}" if shown else point(dominated[-1])
        text += (
            f"; {len(dominated)} more screened point{'' if one else 's'}, {shown}, "
            f"{'is' if one else 'are'} dominated once planned "
            f"({'its plan slows' if one else 'their plans slow'} down more than the screening "
            "assumed)"
        )
    text += (
        f". With {evaluations} evaluations the front's ends stay short of the single-objective "
        "optima above: the front shows the trade-off, the table the optima."
    )
    return textwrap.fill(text, width=92, break_on_hyphens=False) + "\n"


BLOCKS: tuple[Block, ...] = (
    Block("docs/dynamics.md", "travel–copper front", CORNER_FRONT, energy_front),
    Block("README.md", "study table", STUDY, study_table),
    Block("docs/studies.md", "best robot per part", STUDY, best_per_part),
    Block("docs/studies.md", "J per arm", STUDY, j_per_arm),
)


STATED: tuple[Stated, ...] = (
    # README.md: what the walk-through's numbers say
    Stated(
        "README.md",
        "the torch stays within {} mm of the seam (tolerance 0.5 mm). J = {} is the weighted",
        (WALK_OPTIMIZE,),
        lambda run: (
            printed(r"max tracking error = (\S+) mm")(run)[0],
            printed(r"J = (\S+)  duration")(run)[0],
        ),
    ),
    Stated(
        "README.md",
        "runs at exactly the rated 20 mm/s on **{} % of the path's length**",
        (WALK_OPTIMIZE,),
        printed(r"rated speed on (\S+) % of the path"),
    ),
    # docs/results.md: the first points of the walk-through's ROS message
    Stated(
        "docs/results.md",
        "- positions: [{}, {}, {}, {}, {}, {}] # rad velocities: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0] "
        "# rad/s accelerations: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0] # rad/s² effort: [] "
        "time_from_start: {sec: 0, nanosec: 0} - positions: [{}, {}, {}, {}, {}, {}] "
        "velocities: [{}, {}, {}, {}, {}, {}] accelerations: [{}, {}, {}, {}, {}, {}]",
        (WALK_OPTIMIZE, WALK_EXPORT),
        ros_points,
        minus="-",
    ),
    # docs/cell.md: the unconstrained optimum, where it collides, the optimum in the cell
    Stated(
        "docs/cell.md",
        "without the cell, X = ({}, {}, {}, {}, {}, {}) (J = {},",
        (CORNER,),
        lambda run: (*placement(run), printed(r"J = (\S+)  duration")(run)[0]),
    ),
    Stated(
        "docs/cell.md",
        "$ trackplan plan cases/paper-corner-cell.yaml --placement {} {} {} {} {} {} ",
        (CORNER,),
        placement,
        minus="-",
    ),
    Stated(
        "docs/cell.md",
        "(`trackplan map cases/paper-corner-cell.yaml --rpy {} {} {} --z {}`)",
        (CORNER,),
        lambda run: (*placement(run)[3:], placement(run)[2]),
        minus="-",
    ),
    Stated(
        "docs/cell.md",
        "finds X = ({}, {}, {}, {}, {}, {}), feasible with J = {} and the clearance kept "
        "everywhere by the exact check (least distance {} mm,",
        (CORNER_CELL,),
        lambda run: (
            *placement(run),
            printed(r"J = (\S+)  duration")(run)[0],
            printed(r"min clearance = (\S+) mm")(run)[0],
        ),
    ),
    # docs/tool.md
    Stated(
        "docs/tool.md",
        "finds J = {}, {} s, feasible; `trackplan plan` at the case's example placement (the "
        "inner spin search picks {} rad) gives J = {}, {} s, and `trackplan check` verifies "
        "it (largest tool axis deviation {} rad,",
        (TWO_FACES, TWO_FACES_PLAN, TWO_FACES_CHECK),
        lambda search, plan, _check: (
            *j_duration(search),
            f"{_json(plan)['spin']['value']:.2f}",
            *j_duration(plan),
            f"{_json(plan)['max_orientation_error']:.3f}",
        ),
    ),
    Stated(
        "docs/tool.md",
        "evaluations) finds a feasible placement with J = {}, {} s; `trackplan plan` at the "
        "case's example placement (that one, rounded) plans feasibly with J = {}, {} s,",
        (PIPE_FILLET, PIPE_FILLET_PLAN),
        lambda search, plan: (*j_duration(search), *j_duration(plan)),
    ),
    Stated(
        "docs/tool.md",
        "and plans feasibly: J = {}, {} s;",
        (CIRCLE_FREE_PLAN,),
        j_duration,
    ),
    Stated(
        "docs/tool.md",
        "(GA, seed 0) finds J = {}, {} s — below the {} of the paper's constant tool",
        (CIRCLE_FREE, CIRCLE_PAPER),
        lambda search, paper: (*j_duration(search), f"{float(j_duration(paper)[0]):.2f}"),
    ),
    # docs/dynamics.md: travel against copper loss on the corner case, the payload's search
    Stated(
        "docs/dynamics.md",
        "| travel-optimal (`--objective travel`, the default) | ({}, {}, {}, {}, {}, {}) | **{}** "
        "| {} s | {} (N·m)²·s | {} J | {} |",
        (CORNER,),
        energy_row,
    ),
    Stated(
        "docs/dynamics.md",
        "| copper-optimal (`--objective copper`) | ({}, {}, {}, {}, {}, {}) | {} | {} s "
        "| **{} (N·m)²·s** | {} J | {} |",
        (CORNER_COPPER,),
        energy_row,
    ),
    Stated(
        "docs/dynamics.md",
        "| the paper's GA result (`placement.example`) | ({}, {}, {}, {}, {}, {}) | {} | {} s "
        "| {} (N·m)²·s | {} J | {} |",
        (CORNER_PAPER,),
        energy_row,
    ),
    Stated(
        "docs/dynamics.md",
        "wastes energy: {} % more copper loss and {} times the positive mechanical work of the "
        "copper-optimal placement, for {} % less joint travel. The paper's own optimum is worse "
        "than both on J, copper loss, mechanical work and peak torque ({} % more copper loss "
        "and {} times the mechanical work",
        (CORNER, CORNER_COPPER, CORNER_PAPER),
        energy_ratios,
    ),
    Stated(
        "docs/dynamics.md",
        "pitches the path's frame by π/2 ({} rad)",
        (CORNER_COPPER,),
        lambda run: (placement(run, 3)[4],),
    ),
    Stated(
        "README.md",
        "the paper's travel-optimal corner draws {} % more copper loss than the copper-optimal",
        (CORNER, CORNER_COPPER, CORNER_PAPER),
        lambda *runs: energy_ratios(*runs)[:1],
    ),
    Stated(
        "docs/dynamics.md",
        "and finds a feasible one: X = ({}, {}, {}, {}, {}, {}), J = {}, {} s (seed 0)",
        (PAYLOAD,),
        lambda run: (
            *placement(run, 3),
            f"{_json(run)['objective']:.3f}",
            f"{_json(run)['duration']:.2f}",
        ),
    ),
    # docs/seams.md: the shipped bracket's cycle
    Stated(
        "docs/seams.md",
        "| sequence at X = ({}, {}, {}, {}, {}, {}) | cycle time |",
        (BRACKET4,),
        printed(r"placement X = \((\S+), (\S+), (\S+), (\S+), (\S+), (\S+)\)"),
    ),
    Stated(
        "docs/seams.md",
        "| optimised: boss →, gusset ←, rib-right →, rib-left ← | {} s | {} s | {} s | {} |",
        (BRACKET4,),
        printed(
            r"cycle time = (\S+) s \(welding (\S+) s, approach, retract and air (\S+) s\)"
            r"  J = (\S+)"
        ),
    ),
    Stated(
        "docs/seams.md",
        "`approach_deviation` (result.json), {} mm for the 3 cm approach of the shipped case",
        (BRACKET4,),
        lambda run: (f"{_json(run)['approach_deviation'] * 1e3:.2f}",),
    ),
    Stated(
        "docs/seams.md",
        "and the air moves between seams take {}–{} s each",
        (BRACKET4,),
        lambda run: tuple(
            f"{pick(m['duration'] for m in _json(run)['moves'] if m['kind'] == 'air'):.1f}"
            for pick in (min, max)
        ),
    ),
    Stated(
        "docs/seams.md",
        "each seam's tracking (worst {} mm of 0.5 mm, at the gusset's sharp corner blend)",
        (BRACKET4,),
        worst_gusset,
    ),
    Stated(
        "docs/seams.md",
        "and the clearance (least {} mm, the forearm to the plate, of {} mm required)",
        (BRACKET4,),
        printed(r"min clearance = (\S+) mm \(link 3 – plate at t = \S+ s; required (\S+?)\.0 mm\)"),
    ),
    # docs/paper.md: what its console blocks print, restated in its tables and prose
    Stated(
        "docs/paper.md",
        "| status | limits violated | feasible | | duration | {} s | {} s | "
        "| J (Eq. 8) | {} | {} |",
        (LINE_PAPER, LINE_SMOOTH),
        durations_then_js,
    ),
    Stated(
        "docs/paper.md",
        "| duration | {} s | {} s | | J (Eq. 8) | **{}** (paper: 0.9433) | {} |",
        (CORNER_PAPER_TIMING, CORNER_SMOOTH),
        durations_then_js,
    ),
    Stated(
        "docs/paper.md",
        "(Eq. 10 arc: β = 68.2°, r = 4.55 mm, 8.9 mm long) | {} mm (G2 blend) |",
        (CORNER_SMOOTH,),
        printed(r"max tracking error = (\S+) mm"),
    ),
    Stated(
        "docs/paper.md",
        "J = {} at the published X (paper timing, limits violated), {} in smooth timing "
        "(feasible); the search finds {} |",
        (CORNER_PAPER_TIMING, CORNER_SMOOTH, CORNER),
        lambda paper, smooth, search: (
            j_duration(paper)[0],
            j_duration(smooth)[0],
            f"{float(j_duration(search)[0]):.2f}",
        ),
    ),
    Stated(
        "docs/paper.md",
        "({} in paper timing, {} in smooth timing at this X)",
        (CORNER_PAPER_TIMING, CORNER_SMOOTH),
        lambda paper, smooth: (j_duration(paper)[0], j_duration(smooth)[0]),
    ),
    Stated(
        "docs/paper.md",
        "The arc runs N = 60 periods at {} m/s",
        (CORNER_PAPER_TIMING,),
        printed(r"min corner speed = (\S+) m/s"),
    ),
    Stated(
        "docs/paper.md",
        "({} s), tracking error 33 nm.",
        (CIRCLE_PAPER_TIMING,),
        lambda run: (j_duration(run)[1],),
    ),
    Stated(
        "docs/paper.md",
        "Smooth mode: feasible, {} s.",
        (CIRCLE_PAPER,),
        lambda run: (j_duration(run)[1],),
    ),
    *(
        Stated(
            "docs/tool.md",
            f"| seam-weld-{spin} | {label} | yes | {{}} | {{}} s | {{}} |",
            (SEAM_WELD.format(spin, spin),),
            lambda run: (*j_duration(run), printed(r"found in (\d+) evaluations")(run)[0]),
        )
        for spin, label in (("fixed", "fixed (0)"), ("free", "free"))
    ),
)
