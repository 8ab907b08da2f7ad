"""Self-contained HTML reports (the page is built in :mod:`compare.report`).

Kept as the import path of the CLI and of users: :func:`write_report`,
:func:`write_index`, :func:`render_report`, and the plot functions.
"""

from .report.page import (MAX_TABLE_ROWS, banner, bracket, render_report, write_index,
                          write_report)
from .report.plots import (N_WORST, corner_limits, plot_axes, plot_gaps, plot_speed,
                           plot_toolpath)

__all__ = ["MAX_TABLE_ROWS", "N_WORST", "banner", "bracket", "corner_limits", "plot_axes",
           "plot_gaps", "plot_speed", "plot_toolpath", "render_report", "write_index",
           "write_report"]
