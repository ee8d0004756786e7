"""Progress bars for long runs (tqdm on standard error)."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator

from tqdm import tqdm


@contextlib.contextmanager
def time_progress(end_time_s: float, label: str, enabled: bool = True) -> Iterator[Callable[[float], None] | None]:
    """A callback ``progress(t)`` advancing a bar over simulated time, or None when disabled."""
    if not enabled:
        yield None
        return
    with tqdm(total=end_time_s, desc=label, unit="sim s", bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s "
              "[{elapsed}<{remaining}]") as bar:
        def progress(t: float) -> None:
            bar.update(t - bar.n)
        yield progress
        bar.update(end_time_s - bar.n)
