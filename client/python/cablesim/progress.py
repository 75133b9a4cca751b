"""Progress of long calls: a tqdm bar when tqdm is installed, else a line on
standard error now and then, or a function of (done, total)."""

import sys
import time
from typing import Callable, Optional, Union

Progress = Union[None, bool, Callable[[float, Optional[float]], None]]


class Reporter:
    """Reports `done` out of `total` (simulated seconds, or items) as
    `progress` asks: None/False nothing; True a tqdm bar (or a plain line at
    most every 2 s without tqdm); a function called at every update."""

    def __init__(self, progress: Progress, unit: str, total: Optional[float] = None,
                 label: str = ""):
        self.progress, self.unit, self.total, self.label = progress, unit, total, label
        self.bar = None
        self.done = 0.0
        self.last_line = 0.0
        if progress is True:
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=total, unit=unit, desc=label or None, leave=False)
            except ImportError:
                self.bar = None

    def update(self, done: float, total: Optional[float] = None) -> None:
        if total is not None:
            self.total = total
            if self.bar is not None and self.bar.total != total:
                self.bar.total = total
        if done < self.done:
            return
        step, self.done = done - self.done, done
        if callable(self.progress):
            self.progress(done, self.total)
        elif self.progress is True and self.bar is not None:
            self.bar.update(step)
        elif self.progress is True and time.monotonic() - self.last_line >= 2.0:
            self.last_line = time.monotonic()
            of = " of %.6g" % self.total if self.total else ""
            sys.stderr.write("cablesim: %s%.6g%s %s\n" % (
                self.label + ": " if self.label else "", done, of,
                "items" if self.unit == "item" else "s"))

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
