"""What every command shares: the typer app, output helpers and argument checks.

Every argument is checked before any work starts (a search may run for minutes): the
output folder can be written, numbers are finite, names are known. A bad one raises
:class:`~trackplan.errors.CaseError` naming the option: exit code 2.
"""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

import trackplan
from trackplan.choices import Method, Timing, choose
from trackplan.errors import CaseError

if TYPE_CHECKING:  # imported where used: --help and usage errors need none of them
    import numpy as np
    from rich.console import Console

    from trackplan.case import Case

PIPE_WIDTH = 160
"""Width of tables written to something other than a terminal, characters."""

app = typer.Typer(
    name="trackplan",
    help="Offline trajectory planning for robots following a path, with placement search.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


@app.callback()
def _options(
    debug: Annotated[
        bool,
        typer.Option("--debug", help="Print tracebacks of internal errors (or TRACKPLAN_DEBUG=1)."),
    ] = False,
) -> None:
    """Offline trajectory planning for robots following a path, with placement search."""
    # main() reads --debug from the arguments itself: it must know before parsing succeeds.


def error(line: str) -> None:
    """One line on stderr."""
    print(line, file=sys.stderr, flush=True)


def console() -> Console:
    """A console on the current stdout (created per command, so tests can capture it).

    Output that is not a terminal (a pipe, a file, a test) is laid out 160 columns wide
    rather than rich's 80, so that tables keep their numbers whole.
    """
    from rich.console import Console

    return Console(highlight=False, width=None if sys.stdout.isatty() else PIPE_WIDTH)


def shipped_cases_dir() -> Path:
    """The ``cases/`` folder next to the package (present in a source checkout)."""
    return Path(trackplan.__file__).resolve().parents[1] / "cases"


def load_each(files: list[Path], *, assume_limits: bool = False) -> list[tuple[Path, Case | None]]:
    """Load case files one by one; a bad one is reported on stderr and comes with None.

    ``assume_limits`` is as for :func:`~trackplan.io.case_file.load_case` (``--assume-limits``).
    """
    from trackplan.io.case_file import load_case

    loaded: list[tuple[Path, Case | None]] = []
    for file in files:
        try:
            loaded.append((file, load_case(file, assume_limits=assume_limits)))
        except CaseError as exc:
            error(exc.one_line())
            loaded.append((file, None))
    return loaded


# --------------------------------------------------------------------------- options

PlacementOption = Annotated[
    tuple[float, float, float, float, float, float] | None,
    typer.Option(
        "--placement",
        help="X Y Z ROLL PITCH YAW of the path's frame in the robot base frame (m, rad); "
        "default: the case's placement.example.",
        show_default=False,
    ),
]
TimingOption = Annotated[
    str | None,
    typer.Option("--timing", help="smooth or paper (default: the case's task.timing)."),
]

AssumeLimitsOption = Annotated[
    bool,
    typer.Option(
        "--assume-limits",
        help="For a URDF robot without acceleration/jerk limits: assume acceleration = "
        "velocity / 0.25 s and jerk = acceleration / 0.1 s (recorded in result.json).",
    ),
]

MAX_PLACEMENT = 1.0e3
"""Largest |value| of a --placement entry: m for x, y, z and rad for the angles."""


def placement_option(
    values: tuple[float, ...] | None, options: tuple[str, ...] = ("--placement",) * 6
) -> np.ndarray | None:
    """Check a --placement value: six finite numbers of sane size.

    ``options`` names the command-line option of each entry (``map`` takes Z from ``--z``
    and the angles from ``--rpy``).

    Raises
    ------
    CaseError
        Naming the entry's option and the bad entry.
    """
    import numpy as np

    if values is None:
        return None
    names = ("X", "Y", "Z", "ROLL", "PITCH", "YAW")
    for name, value, option in zip(names, values, options, strict=True):
        if not math.isfinite(value) or abs(value) > MAX_PLACEMENT:
            raise CaseError(
                f"{name} must be a finite number with |{name}| ≤ {MAX_PLACEMENT:g}, got {value!r}",
                key=option,
            )
    return np.asarray(values, dtype=float)


def placement(case: Case, values: np.ndarray | None) -> np.ndarray:
    """The placement given on the command line, else the case's example placement."""
    import numpy as np

    if values is not None:
        return values
    if case.bounds.example is None:
        raise CaseError(
            "no placement: give --placement X Y Z ROLL PITCH YAW or set placement.example",
            file=case.source,
            key="placement.example",
        )
    return np.asarray(case.bounds.example, dtype=float)


def run_positioner(case: Case, run: Path) -> Case:
    """The case with its positioner where a run folder's ``result.json`` records it
    (:func:`~trackplan.io.results.recorded_positioner`); the case itself for a CSV file or a
    case without a positioner."""
    import json

    from trackplan.io.results import recorded_positioner
    from trackplan.run_files import RESULT_FILE

    file = Path(run) / RESULT_FILE
    if case.positioner is None or not Path(run).is_dir() or not file.is_file():
        return case
    try:
        summary = json.loads(file.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        summary = {}
    return recorded_positioner(case, summary if isinstance(summary, dict) else {}, str(file))


def run_placement(run: Path) -> np.ndarray | None:
    """The placement a run folder's ``result.json`` records (None for a CSV file).

    Read by ``check`` when no --placement is given: a run is checked where it was planned.

    Raises
    ------
    CaseError
        When ``result.json`` holds no placement of six finite numbers of sane size.
    """
    import json

    import numpy as np

    from trackplan.case import PLACEMENT_KEYS
    from trackplan.run_files import RESULT_FILE

    file = Path(run) / RESULT_FILE
    if not Path(run).is_dir() or not file.is_file():
        return None
    try:
        recorded = json.loads(file.read_text(encoding="utf-8")).get("placement")
        values = [float(recorded[key]) for key in PLACEMENT_KEYS]
    except (OSError, UnicodeDecodeError, ValueError, TypeError, KeyError, AttributeError):
        raise CaseError(
            f"expected {{{', '.join(PLACEMENT_KEYS)}}} (m, rad): give --placement instead",
            file=str(file),
            key="placement",
        ) from None
    if not all(math.isfinite(value) and abs(value) <= MAX_PLACEMENT for value in values):
        raise CaseError(
            f"expected finite numbers with |value| ≤ {MAX_PLACEMENT:g}, got {values}",
            file=str(file),
            key="placement",
        )
    return np.asarray(values, dtype=float)


SAMPLE_TIME_TOLERANCE = 1e-6
"""A trajectory's sample k may lie this share of the sample time off t = k · Ts."""


def check_sample_times(t: np.ndarray, sample_time: float, file: str) -> None:
    """Check that a trajectory's times are the case's samples: t_k = k · Ts from t = 0.

    The checker takes the samples as the controller plays them, one per ``sample_time``
    (docs/guarantees.md); a trajectory resampled, stretched or shifted in time would be
    checked at the wrong rate. Each t_k may differ from k · Ts by at most
    :data:`SAMPLE_TIME_TOLERANCE` · Ts.

    Raises
    ------
    CaseError
        Naming the file's line (the header is line 1) of the first sample off its time.
    """
    import numpy as np

    tolerance = SAMPLE_TIME_TOLERANCE * sample_time
    expected = np.arange(len(t)) * sample_time
    off = np.flatnonzero(~(np.abs(t - expected) <= tolerance))
    if not off.size:
        return
    k = int(off[0])
    start = "" if k else " (a trajectory starts at t = 0)"
    raise CaseError(
        f"line {k + 2}: t = {t[k]:.9g} s, expected {expected[k]:.9g} s{start}: sample {k} "
        f"of the case's task.sample_time = {sample_time:g} s, within "
        f"{SAMPLE_TIME_TOLERANCE:g} · Ts; resample the trajectory at the case's sample time",
        file=file,
        key="t",
    )


def timing_option(value: str | None) -> Timing | None:
    """Check a --timing value."""
    return None if value is None else choose(Timing, value, "--timing")


def method_option(value: str | None) -> Method | None:
    """Check a --method value (an empty name is refused too)."""
    return None if value is None else choose(Method, value, "--method")


OUTPUT_OPTIONS = {"--out": "folder", "--output": "file"}
"""Options naming where a command writes, and what they name."""


def refuse_empty_outputs(args: list[str]) -> None:
    """Refuse an empty ``--out`` or ``--output`` on the command line, before parsing.

    typer turns ``--out ""`` into ``Path("")``, which is ``Path(".")``: the command would
    write into the current folder. The raw arguments are the only place the two differ.

    Raises
    ------
    CaseError
        Naming the option.
    """
    for i, arg in enumerate(args):
        if arg == "--":
            return
        name, equals, value = arg.partition("=")
        if name not in OUTPUT_OPTIONS:
            continue
        given = value if equals else args[i + 1] if i + 1 < len(args) else None
        if given is not None and not given.strip():
            what = OUTPUT_OPTIONS[name]
            example = "runs/x" if what == "folder" else "trajectory.yaml"
            raise CaseError(
                f"an empty name is not a {what}; give the output {what}, e.g. {name} {example}",
                key=name,
            )


def output_folder(out: Path, option: str = "--out") -> Path:
    """Check that ``out`` can be the folder of a run's files, before any work starts.

    It may exist (a folder: its earlier run's files are replaced) or not (it is created,
    with any missing parents). It must not be a file, lie under a file, or be somewhere
    this process cannot write.

    Raises
    ------
    CaseError
        Naming ``option`` and what is in the way.
    """
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise CaseError(f"{str(out)!r} is a file, expected a folder", key=option)
    existing = out
    while not existing.exists():
        if existing.parent == existing:
            break
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise CaseError(f"{str(out)!r} lies under the file {str(existing)!r}", key=option)
    if not os.access(existing, os.W_OK | os.X_OK):
        raise CaseError(f"cannot write into {str(existing)!r} (permission denied)", key=option)
    return out
