"""``python -m trackplan``: the same as the ``trackplan`` command."""

from trackplan.cli import main

raise SystemExit(main())
