"""The ``trackplan`` command line (entry point :func:`main`).

Commands, one module per group, each a thin parse → API → save → exit code:
:mod:`~trackplan.cli.cases` (``validate``, ``robots``, ``cases``),
:mod:`~trackplan.cli.parts` (``part``),
:mod:`~trackplan.cli.plan` (``plan``, ``check``, ``export``) and
:mod:`~trackplan.cli.search` (``optimize``, ``demo``). Text summaries are in
:mod:`~trackplan.cli.summaries`, argument checks in :mod:`~trackplan.cli.common`.

Exit codes: 0 ok, 1 internal error, 2 bad input, 3 infeasible (:class:`ExitCode`), and
128 + the signal number when SIGINT (130) or SIGTERM (143) stopped the command.
:func:`main` never raises: a :class:`~trackplan.errors.CaseError` becomes one line on
stderr and exit code 2; any other exception one line ``internal error: ...`` and exit
code 1, with the traceback only under ``trackplan --debug`` or ``TRACKPLAN_DEBUG=1``.

The ``trackplan`` command and ``python -m trackplan`` run :func:`run_and_exit`, which ends
the process without the interpreter's teardown (:func:`exit_process`).

This module imports nothing heavy, so that Ctrl-C while the command starts up (numpy,
typer and the planner are imported inside :func:`main`) ends with exit 130 and no traceback.
"""

from __future__ import annotations

import atexit
import enum
import gc
import os
import signal
import sys
import threading
from typing import NoReturn


class ExitCode(enum.IntEnum):
    """Process exit codes of every command."""

    OK = 0
    INTERNAL_ERROR = 1
    BAD_INPUT = 2
    INFEASIBLE = 3
    INTERRUPTED = 128 + signal.SIGINT
    TERMINATED = 128 + signal.SIGTERM


DEBUG_ENV = "TRACKPLAN_DEBUG"
"""Set to 1 to print tracebacks of internal errors."""


def main(argv: list[str] | None = None) -> int:
    """Run the command line and return its exit code; never raises.

    Parameters
    ----------
    argv
        The arguments after the program name; ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        An :class:`ExitCode` value.
    """
    args = sys.argv[1:] if argv is None else list(argv)
    # At exit, Python collects every object left, numba's and LLVM's many included: 0.8 s of
    # CPU under load after a search, for memory the process returns anyway. Freezing them
    # first skips that collection (each is still freed when its last reference goes).
    atexit.unregister(gc.freeze)
    atexit.register(gc.freeze)
    debug = "--debug" in args or os.environ.get(DEBUG_ENV, "") not in ("", "0")
    try:
        from trackplan.cli.app import run

        return run(args, debug=debug)
    except KeyboardInterrupt as exc:  # during start-up, or a second signal while writing
        print("interrupted", file=sys.stderr, flush=True)
        return 128 + int(getattr(exc, "signum", signal.SIGINT))


def run_and_exit() -> NoReturn:
    """The ``trackplan`` command: run :func:`main` on ``sys.argv``, then :func:`exit_process`."""
    exit_process(main())


def exit_process(code: int) -> NoReturn:
    """End the process with exit code ``code``.

    Where no other thread runs, this skips the interpreter's teardown (freeing every module
    and object one by one: 0.12 s after a search, for memory the process returns anyway):
    the atexit handlers run, stdout and stderr are flushed, then the process ends.
    """
    if threading.active_count() == 1:
        atexit._run_exitfuncs()
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        except (OSError, ValueError):  # a closed pipe: the interpreter reports it as usual
            sys.exit(code)
        os._exit(code)
    sys.exit(code)
