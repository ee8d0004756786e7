"""What every figure shares: figures made without pyplot, colour-blind-safe line styles, the map colour
scale, and saving as SVG beside the raster file.

A figure is a :class:`matplotlib.figure.Figure` of its own (:func:`figure`), drawn and saved without
pyplot: drawing one neither chooses nor switches matplotlib's backend, opens no window and leaves no
figure behind in a user's session (a notebook keeps its backend; ``rpdrill`` needs no display).

Lines: the Okabe-Ito colours (distinct for the common colour-vision deficiencies; yellow left out,
too pale on white), then the same colours dashed, dotted and dash-dotted, each line with its own
marker, so that 28 lines stay distinguishable without colour. Maps: cividis (perceptually
uniform, readable with deuteranopia and in grey).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib
from matplotlib.figure import Figure
from matplotlib.layout_engine import ConstrainedLayoutEngine

OKABE_ITO = ("#000000", "#E69F00", "#56B4E9", "#009E73", "#0072B2", "#D55E00", "#CC79A7")
LINE_STYLES = ("-", "--", ":", "-.")
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "<", ">", "h", "*", "p")
MAP_COLORMAP = "cividis"
NO_RESULT_COLOR = "0.85"  # the background of map cells without a result (failed runs)


@dataclass(frozen=True)
class LineStyle:
    color: str
    linestyle: str
    marker: str

    def kwargs(self) -> dict[str, str]:
        return {"color": self.color, "linestyle": self.linestyle, "marker": self.marker}


def figure(**options: Any) -> Figure:
    """A new figure outside pyplot (module doc); ``options`` as for :class:`~matplotlib.figure.Figure`
    (``figsize``, ``layout``); its axes by ``figure.subplots``."""
    return Figure(**options)


def line_styles(count: int) -> list[LineStyle]:
    """``count`` distinct styles: the colours solid, then dashed, dotted, dash-dotted; markers cycle
    on their own."""
    return [LineStyle(OKABE_ITO[k % len(OKABE_ITO)], LINE_STYLES[k // len(OKABE_ITO) % len(LINE_STYLES)],
                      MARKERS[k % len(MARKERS)]) for k in range(count)]


def save(fig: Figure, path: Path, dpi: int = 120) -> list[Path]:
    """Write ``fig`` to ``path`` and, unless ``path`` is an SVG, to an SVG beside it; close it. A figure
    with the constrained layout fits its legends and labels already, and its layout, solved for the
    first file, is kept for the second; any other is cropped to what it draws (``bbox_inches="tight"``,
    one more draw per file). PNGs are compressed at zlib level 1 (a study figure of 1080 x 1440 pixels:
    0.043 s and 188 kB against 0.058 s and 171 kB at the default level 6). A figure outside pyplot needs
    no closing: it is freed with its last reference."""
    paths = [path] + ([path.with_suffix(".svg")] if path.suffix != ".svg" else [])
    constrained = isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine)
    for target in paths:
        options = {"pil_kwargs": {"compress_level": 1}} if target.suffix == ".png" else {}
        fig.savefig(target, dpi=dpi, bbox_inches=None if constrained else "tight", **options)
        if constrained:
            keep_layout(fig)  # laid out: the next file is drawn as this one was
    return paths


def keep_layout(fig: Figure) -> None:
    """Keep ``fig``'s layout as it was last solved: no layout engine at all. (``set_layout_engine("none")``
    leaves a placeholder engine, for which every ``savefig``, and so every animation frame grabbed, first
    draws the whole figure once more: the timeseries figure's two files took 4 draws, the animation's 60
    frames 120.) The rc settings that would choose an engine for None are set aside for the call."""
    with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
        fig.set_layout_engine(None)
