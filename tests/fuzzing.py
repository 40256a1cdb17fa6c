"""Seeded mutants of the shipped case, robot and URDF files, and a harness that runs the CLI.

Used by ``tests/test_fuzz.py`` (a fast subset) and ``python -m benchmarks robustness`` (a
larger run). A mutant replaces, deletes or duplicates one value of a shipped file, or
damages its text (a URDF: one attribute's value, or its XML; the points file ``bead.csv``:
a bad number, separator or row); the harness runs ``validate`` and, for mutants that
validate, ``plan``, and classifies the outcome. The contract: no exit 1, no traceback, no
warning on stderr, every run within :data:`RUN_LIMIT_S`, every exit-2 message one line
naming the key (or line) at fault.
"""

from __future__ import annotations

import contextlib
import io
import re
import shutil
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from trackplan.cli import main

ROOT = Path(__file__).resolve().parent.parent
CASE_FILES = sorted((ROOT / "cases").glob("*.yaml"))
ROBOT_FILES = sorted((ROOT / "robots").glob("*.yaml"))
URDF_FILES = sorted((ROOT / "trackplan" / "robots" / "library").glob("*.urdf"))
RUN_LIMIT_S = 10.0
"""Longest time one command may take on a mutant, s."""

HOSTILE_VALUES: tuple[Any, ...] = (
    0,
    -1,
    1e308,
    -1e308,
    1e-300,
    10**30,
    float("nan"),
    float("inf"),
    "",
    "yes",
    "1:30",
    "x" * 5000,
    None,
    True,
    [],
    {},
    [1, 2],
    [0.0, 0.0, 0.0],
    [1e200, 0, 0],
    {"a": 1},
    0.5,
    2.0,
    1e6,
)

TEXT_DAMAGE = ("delete line", "duplicate line", "truncate", "indent", "bracket", "alias")

CSV_DAMAGE: tuple[str, ...] = (
    "0.3_1",
    "\uff10.2",
    "nan",
    "inf",
    "1e999",
    "0x1p-3",
    "",
    "x",
    "1;2;3",
    "1\t2\t3",
    "1,2,3,4",
    "1,2",
    "# note",
    "\ufeffx,y,z",
    "x,y,z",
)
"""Cell or row replacements of a points file's mutants (a bad number, separator or row)."""

HOSTILE_ATTRIBUTES = (
    "nan",
    "inf",
    "-1e308",
    "1e308",
    "0",
    "-1",
    "1e-300",
    "1 2 3 4",
    "0 0 1e-300",
    "",
    "x",
    "0 0 0",
)
"""Values put into one attribute of a URDF."""

XML_DAMAGE = ("unquote", "unclose", "duplicate joint", "truncate")


def _paths(data: Any, prefix: tuple = ()) -> list[tuple]:
    """Every key path of a loaded YAML document (mappings and lists)."""
    found = [prefix] if prefix else []
    if isinstance(data, dict):
        for key, value in data.items():
            found += _paths(value, (*prefix, key))
    elif isinstance(data, list):
        for i, value in enumerate(data):
            found += _paths(value, (*prefix, i))
    return found


def _set(data: Any, path: tuple, value: Any, delete: bool = False) -> None:
    node = data
    for part in path[:-1]:
        node = node[part]
    if delete:
        del node[path[-1]]
    else:
        node[path[-1]] = value


def mutate(text: str, rng: np.random.Generator) -> str:
    """One mutant of a YAML file's text."""
    if rng.random() < 0.25:
        return _damage_text(text, rng)
    data = yaml.safe_load(text)
    paths = _paths(data)
    path = paths[int(rng.integers(len(paths)))]
    if rng.random() < 0.15:
        _set(data, path, None, delete=True)
    else:
        _set(data, path, HOSTILE_VALUES[int(rng.integers(len(HOSTILE_VALUES)))])
    return yaml.safe_dump(data, sort_keys=False, allow_unicode=True)


def mutate_points(text: str, rng: np.random.Generator) -> str:
    """One mutant of a points file's text: a cell or a row replaced, a row deleted or
    repeated, the file cut short, or a byte order mark added."""
    lines = text.splitlines()
    k = int(rng.integers(len(lines)))
    damage = CSV_DAMAGE[int(rng.integers(len(CSV_DAMAGE)))]
    kind = int(rng.integers(5))
    if kind == 0:  # one cell
        cells = lines[k].split(",")
        cells[int(rng.integers(len(cells)))] = damage
        lines[k] = ",".join(cells)
    elif kind == 1:  # a whole row
        lines[k] = damage
    elif kind == 2:
        del lines[k]
    elif kind == 3:
        lines.insert(k, lines[k])
    else:
        return ("\ufeff" if rng.random() < 0.5 else "") + text[: int(rng.integers(len(text)))]
    return "\n".join(lines) + "\n"


def _damage_text(text: str, rng: np.random.Generator) -> str:
    lines = text.splitlines()
    k = int(rng.integers(len(lines)))
    kind = TEXT_DAMAGE[int(rng.integers(len(TEXT_DAMAGE)))]
    if kind == "delete line":
        del lines[k]
    elif kind == "duplicate line":
        lines.insert(k, lines[k])
    elif kind == "truncate":
        return text[: int(rng.integers(len(text)))]
    elif kind == "indent":
        lines[k] = "   " + lines[k]
    elif kind == "bracket":
        lines[k] = lines[k].replace("]", "", 1) if "]" in lines[k] else lines[k] + " ["
    else:
        lines.insert(0, "anchors: &a [1, 2, 3]")
        lines[min(k + 1, len(lines) - 1)] += " *a"
    return "\n".join(lines) + "\n"


def mutate_urdf(text: str, rng: np.random.Generator) -> str:
    """One mutant of a URDF's text: one attribute's value replaced, or its XML damaged."""
    if rng.random() < 0.3:
        kind = XML_DAMAGE[int(rng.integers(len(XML_DAMAGE)))]
        if kind == "unquote":  # <axis xyz=0 0 1/>: yourdfpy alone would drop the attribute
            found = list(re.finditer(r'="([^"]*)"', text))
            match = found[int(rng.integers(len(found)))]
            return text[: match.start()] + "=" + match.group(1) + text[match.end() :]
        if kind == "unclose":
            return text.replace("</robot>", "")
        if kind == "duplicate joint":
            joints = re.findall(r"<joint .*?</joint>", text, flags=re.S)
            joint = joints[int(rng.integers(len(joints)))]
            return text.replace(joint, joint + "\n" + joint, 1)
        return text[: int(rng.integers(len(text)))]
    found = list(re.finditer(r'(\w+)="([^"]*)"', text))
    match = found[int(rng.integers(len(found)))]
    value = HOSTILE_ATTRIBUTES[int(rng.integers(len(HOSTILE_ATTRIBUTES)))]
    return text[: match.start(2)] + value + text[match.end(2) :]


@dataclass
class FuzzCounts:
    """Outcomes of a fuzz run."""

    runs: int = 0
    exit_codes: dict[int, int] = field(default_factory=dict)
    tracebacks: int = 0
    warnings: list[str] = field(default_factory=list)
    hangs: int = 0
    bad_messages: list[str] = field(default_factory=list)
    internal_errors: list[str] = field(default_factory=list)
    slowest_s: float = 0.0

    def add(self, code: int, err: str, seconds: float) -> None:
        """Count one command's outcome."""
        self.runs += 1
        self.exit_codes[code] = self.exit_codes.get(code, 0) + 1
        self.slowest_s = max(self.slowest_s, seconds)
        if "Traceback" in err:
            self.tracebacks += 1
        if "Warning" in err:  # numpy's RuntimeWarning, a library's log line
            self.warnings.append(err.strip()[:300])
        if seconds > RUN_LIMIT_S:
            self.hangs += 1
        if code == 1:
            self.internal_errors.append(err.strip()[:300])
        if code == 2 and not _names_the_fault(err):
            self.bad_messages.append(err.strip()[:300])


def _names_the_fault(err: str) -> bool:
    """One line ``file: key: message``, ``file: YAML ... at line L, column C: ...`` or, for a
    URDF, ``file: line L: ...``, ``file: not well-formed XML at line L, ...`` or naming the
    joint or link."""
    lines = err.strip().splitlines()
    if len(lines) != 1:
        return False
    line = lines[0]
    return bool(
        re.search(r"\.(yaml|csv): [\w.\[\]-]+: ", line)
        or re.search(r"at line \d+, column \d+", line)
        or re.search(r"\.(yaml|csv): (the file|case file|robot file|points file)", line)
        or re.search(r"\.csv: line \d+: ", line)
        or re.search(r"\.urdf: (line \d+: |not well-formed XML at line \d+|(joint|link) ')", line)
    )


HIDDEN_WARNINGS = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)
"""Warnings Python's default filters do not print outside ``__main__``."""


def run_cli(args: list[str]) -> tuple[int, str, float]:
    """Run ``trackplan args`` in this process: exit code, stderr, seconds.

    Python warnings (numpy's RuntimeWarning) are recorded, every one, and added to stderr
    as the command line would print them, whatever filter pytest has installed (except
    those Python hides by default, :data:`HIDDEN_WARNINGS`).
    """
    out, err = io.StringIO(), io.StringIO()
    start = time.perf_counter()
    with (
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
        warnings.catch_warnings(record=True) as caught,
    ):
        warnings.simplefilter("always")
        code = main(args)
    shown = "".join(
        f"{w.category.__name__}: {w.message}\n"
        for w in caught
        if not issubclass(w.category, HIDDEN_WARNINGS)
    )
    return code, err.getvalue() + shown, time.perf_counter() - start


def fuzz(folder: Path, n_mutants: int, n_plans: int, seed: int) -> FuzzCounts:
    """Validate ``n_mutants`` mutants and plan up to ``n_plans`` of those that validate.

    Case mutants are written beside copies of the shipped files they refer to; robot
    mutants are referred to by a copy of ``paper-line.yaml``.
    """
    rng = np.random.default_rng(seed)
    shutil.copy(ROOT / "cases" / "bead.csv", folder / "bead.csv")
    base_case = (ROOT / "cases" / "paper-line.yaml").read_text()
    counts = FuzzCounts()
    planned = 0
    # warm-up, not counted: the first plan in a process compiles the numba kernels
    warm = folder / "warm-up.yaml"
    warm.write_text(base_case)
    run_cli(["plan", str(warm), "--out", str(folder / "warm-up"), "--no-report"])
    for i in range(n_mutants):
        options: list[str] = []
        draw = rng.random()
        if URDF_FILES and draw < 0.2:
            urdf = folder / f"arm-{i}.urdf"
            urdf.write_text(
                mutate_urdf(URDF_FILES[int(rng.integers(len(URDF_FILES)))].read_text(), rng)
            )
            text = base_case.replace("robot: puma560", f"robot: {urdf.name}")
            options = ["--assume-limits"]
        elif ROBOT_FILES and draw < 0.35:
            robot = folder / f"robot-{i}.yaml"
            robot.write_text(mutate(ROBOT_FILES[0].read_text(), rng))
            text = base_case.replace("robot: puma560", f"robot: {robot.name}")
        elif draw < 0.5:  # the points file of ur5-bead
            points = folder / f"bead-{i}.csv"
            points.write_text(mutate_points((ROOT / "cases" / "bead.csv").read_text(), rng))
            text = (ROOT / "cases" / "ur5-bead.yaml").read_text()
            text = text.replace("{file: bead.csv}", f"{{file: {points.name}}}")
        else:
            text = mutate(CASE_FILES[int(rng.integers(len(CASE_FILES)))].read_text(), rng)
        case = folder / f"case-{i}.yaml"
        case.write_text(text)
        code, err, seconds = run_cli(["validate", str(case), *options])
        counts.add(code, err, seconds)
        if code == 0 and planned < n_plans:
            planned += 1
            args = ["plan", str(case), "--out", str(folder / f"run-{i}"), "--no-report", *options]
            if "example:" not in text:
                args += ["--placement", "0.3", "0.1", "0.2", "0", "0", "0"]
            code, err, seconds = run_cli(args)
            counts.add(code, err, seconds)
    return counts
