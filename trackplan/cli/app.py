"""Run the typer application: every command module registered, errors mapped to exit codes.

Adding a command
----------------
A command is a thin function on :data:`trackplan.cli.common.app` in the module of its
group that returns an :class:`~trackplan.cli.ExitCode`: parse (typer does it from the
signature, :mod:`trackplan.cli.common` checks the values before any work starts) →
load (:mod:`trackplan.io`) → compute (the pure API) → save (:mod:`trackplan.io`) → exit
code. It raises ``CaseError`` for bad input and lets :func:`run` report it::

    @app.command()
    def plan(
        case: Annotated[Path, typer.Argument(help="Case file.")],
        out: Annotated[Path, typer.Option(help="Output folder.")] = Path("out"),
    ) -> ExitCode:
        \"\"\"Plan the trajectory of one placement.\"\"\"
        out = output_folder(out)
        loaded = load_case(case)
        result = plan(loaded, loaded.bounds.example)
        write_run(out, result, loaded)
        return ExitCode.OK if result.success else ExitCode.INFEASIBLE
"""

from __future__ import annotations

import signal
import traceback

import typer

from trackplan.allocator import keep_freed_memory
from trackplan.cli import ExitCode
from trackplan.cli import batch as _batch  # noqa: F401  (registers its commands)
from trackplan.cli import cases as _cases  # noqa: F401
from trackplan.cli import parts as _parts  # noqa: F401
from trackplan.cli import plan as _plan  # noqa: F401
from trackplan.cli import report_images as _report_images  # noqa: F401
from trackplan.cli import search as _search  # noqa: F401
from trackplan.cli.common import app, error, refuse_empty_outputs
from trackplan.cli.signals import Stopped, forget_stops, last_stop, stopped_by_signal
from trackplan.errors import CaseError


def run(args: list[str], *, debug: bool) -> int:
    """Run one command line; see :func:`trackplan.cli.main`."""
    keep_freed_memory()
    forget_stops()
    try:
        refuse_empty_outputs(args)
        command = typer.main.get_command(app)
        result = command.main(args=args, prog_name="trackplan", standalone_mode=False)
    except CaseError as exc:
        error(exc.one_line())
        return ExitCode.BAD_INPUT
    except typer.TyperException as exc:
        # Usage errors (unknown option, missing argument): typer prints usage and hint.
        show = getattr(exc, "show", None)
        if callable(show):
            show()
        else:
            error(exc.format_message())
        return exc.exit_code
    except typer.Abort:
        error("aborted")
        return ExitCode.INTERNAL_ERROR
    except Stopped as exc:
        error(f"interrupted ({exc})")
        return 128 + exc.signum
    except KeyboardInterrupt:
        error("interrupted")
        return ExitCode.INTERRUPTED
    except Exception as exc:
        interrupt = stopped_by_signal(exc)
        if interrupt is not None:
            error("interrupted")
            return 128 + int(getattr(interrupt, "signum", ExitCode.INTERRUPTED - 128))
        if debug:
            traceback.print_exc()
        error(f"internal error: {type(exc).__name__}: {exc}".replace("\n", " "))
        return ExitCode.INTERNAL_ERROR
    if result == ExitCode.INTERRUPTED and not isinstance(result, ExitCode):
        # typer turns any KeyboardInterrupt (so a Stopped) into a bare exit code 130
        signum = last_stop() or signal.SIGINT
        error(f"interrupted ({signal.Signals(signum).name})")
        return 128 + signum
    return int(result) if isinstance(result, int) else ExitCode.OK
