"""Self-contained HTML reports: one page per program, an index for several.

:mod:`~compare.report.page` builds the page (banner, cards, block table, listing),
:mod:`~compare.report.plots` the plots, :mod:`~compare.report.envelope` reduces long
series to the screen's resolution. ``compare.report_html`` re-exports the public names.
"""

from .page import render_report, write_index, write_report

__all__ = ["render_report", "write_index", "write_report"]
