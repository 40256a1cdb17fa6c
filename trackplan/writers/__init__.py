"""Writers: the export formats behind one protocol, and ``export``.

Each format is a :class:`Writer` (``name``, ``suffix``, ``default_file``,
``write(table, output, **options)``) registered by name in :data:`WRITERS`;
:func:`export` picks one by name or by the output's suffix. The built-in writers are
``csv``, ``json`` and ``ros`` (:mod:`trackplan.writers.trajectory_formats`); a new format
registers with :func:`register_writer`. See ``docs/results.md`` and ``docs/api.md``.
"""

from trackplan.writers.exporter import export, export_trajectory
from trackplan.writers.protocol import (
    WRITERS,
    Writer,
    register_writer,
    writer_for_file,
    writer_named,
)
from trackplan.writers.trajectory_formats import CsvWriter, JsonWriter, RosWriter

for _writer in (CsvWriter(), JsonWriter(), RosWriter()):
    register_writer(_writer)

__all__ = [
    "WRITERS",
    "CsvWriter",
    "JsonWriter",
    "RosWriter",
    "Writer",
    "export",
    "export_trajectory",
    "register_writer",
    "writer_for_file",
    "writer_named",
]
