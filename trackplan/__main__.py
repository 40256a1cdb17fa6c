"""``python -m trackplan``: the same as the ``trackplan`` command."""

from trackplan.cli import run_and_exit

run_and_exit()
