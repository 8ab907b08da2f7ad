"""Progress display for long jobs: on a terminal only, silent with --quiet or when piped."""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import TextIO


@dataclass
class Progress:
    """A one-line progress indicator on stderr.

    It draws only when ``stream`` is a TTY and ``quiet`` is False, and only after the
    job has run for ``delay_s`` (short jobs stay clean). Call it as
    ``progress(message, fraction)``; ``fraction`` in [0, 1] or negative when unknown.

    Attributes
    ----------
    quiet : bool
        Suppress all output.
    stream : TextIO
        Where to draw (stderr).
    delay_s : float
        Seconds before the first draw.
    """

    quiet: bool = False
    stream: TextIO = field(default_factory=lambda: sys.stderr)
    delay_s: float = 1.0
    _t0: float = field(default_factory=time.monotonic)
    _drawn: bool = False

    @property
    def active(self) -> bool:
        """True when progress is drawn at all."""
        return not self.quiet and hasattr(self.stream, "isatty") and self.stream.isatty()

    def __call__(self, message: str, fraction: float = -1.0) -> None:
        """Show ``message`` with a percentage (when ``fraction`` >= 0)."""
        if not self.active or time.monotonic() - self._t0 < self.delay_s:
            return
        pct = f" {100 * min(max(fraction, 0.0), 1.0):5.1f} %" if fraction >= 0 else ""
        self.stream.write(f"\r\x1b[2K{message}{pct}")
        self.stream.flush()
        self._drawn = True

    def done(self) -> None:
        """Clear the line (call once at the end)."""
        if self._drawn:
            self.stream.write("\r\x1b[2K")
            self.stream.flush()
            self._drawn = False
