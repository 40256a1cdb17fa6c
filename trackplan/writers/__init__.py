"""Writers: the export formats behind one protocol, and ``export``.

Each format is a :class:`Writer` (``name``, ``suffix``, ``default_file``, ``folder``,
``write(source, folder, **options) -> names``) registered by name in :data:`WRITERS`;
:func:`export` picks one by name or by the output's suffix, lets it write into a staging
folder and moves its files into place. The trajectory writers are ``csv``, ``json`` and
``ros`` (:mod:`trackplan.writers.trajectory_formats`); the program writers print a
:class:`~trackplan.programs.Program` (:meth:`ExportSource.program`) in a controller's
language. A new format registers with :func:`register_writer`. See ``docs/results.md`` and
``docs/api.md``.
"""

from trackplan.writers.exporter import export, export_files, export_trajectory
from trackplan.writers.fanuc import FanucWriter
from trackplan.writers.krl import KrlWriter
from trackplan.writers.protocol import (
    WRITERS,
    Writer,
    register_writer,
    write_text_files,
    writer_for_file,
    writer_named,
)
from trackplan.writers.rapid import RapidWriter
from trackplan.writers.source import ExportSource
from trackplan.writers.trajectory_formats import CsvWriter, JsonWriter, RosWriter
from trackplan.writers.urscript import UrscriptWriter

# The registry, in the order `--format` lists the formats: the trajectory formats, then
# the controller program writers.
for _writer in (
    CsvWriter(),
    JsonWriter(),
    RosWriter(),
    KrlWriter(),
    RapidWriter(),
    FanucWriter(),
    UrscriptWriter(),
):
    register_writer(_writer)

__all__ = [
    "WRITERS",
    "CsvWriter",
    "ExportSource",
    "FanucWriter",
    "JsonWriter",
    "KrlWriter",
    "RapidWriter",
    "RosWriter",
    "UrscriptWriter",
    "Writer",
    "export",
    "export_files",
    "export_trajectory",
    "register_writer",
    "write_text_files",
    "writer_for_file",
    "writer_named",
]
