"""Plots and the HTML report of a planned placement.

``write_plots`` writes the PNG plots of a run, ``write_report`` the self-contained
``report.html`` (plots embedded, interactive 3D view of the robot); ``write_run_report``
writes both as a run does, the first plot in a forked process on a second core. The ``*_figure``
functions return the figures themselves. matplotlib and plotly are imported only when
a figure is built, so importing this package is cheap.
"""

from trackplan.report.convergence_plot import convergence_figure
from trackplan.report.figures import write_plots
from trackplan.report.html import write_report
from trackplan.report.joints_plot import joints_figure
from trackplan.report.path_plots import path_figure
from trackplan.report.robot_view import VIEW_ID, robot_view_figure, robot_view_spec
from trackplan.report.run_report import write_run_report
from trackplan.report.speed_plot import speed_figure

__all__ = [
    "VIEW_ID",
    "convergence_figure",
    "joints_figure",
    "path_figure",
    "robot_view_figure",
    "robot_view_spec",
    "speed_figure",
    "write_plots",
    "write_report",
    "write_run_report",
]
