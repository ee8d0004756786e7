"""A metric over two parameters as discrete cells, one per grid point: edges halfway between
neighbouring values, nothing interpolated across cells; an axis with at most ``FEW_VALUES`` values
is drawn as equal rows (columns) labelled by value, so that four rock stiffnesses do not look like
a continuum. Cells without a result are grey."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from matplotlib.patches import Patch

from ..display.catalogue import Quantity
from .figure_style import MAP_COLORMAP, NO_RESULT_COLOR

FEW_VALUES = 8
Position = Callable[[float, float], tuple[float, float]]


def _cells(values: list[float], quantity: Quantity) -> tuple[np.ndarray, np.ndarray, bool]:
    """(cell centres, cell edges, as labelled rows) in display units."""
    shown = np.array([quantity.display(v) for v in values])
    if len(shown) <= FEW_VALUES:
        return np.arange(len(shown), dtype=float), np.arange(len(shown) + 1) - 0.5, True
    middle = (shown[1:] + shown[:-1]) / 2
    return shown, np.concatenate([[2 * shown[0] - middle[0]], middle, [2 * shown[-1] - middle[-1]]]), False


def cell_map(fig: Any, ax: Any, xs: list[float], ys: list[float], z: np.ndarray, x: Quantity, y: Quantity,
             z_quantity: Quantity) -> Position:
    """Draw ``z`` (SI; rows along ``ys``, columns along ``xs``, both increasing, SI) as cells with a
    colour bar; the function that places an (x, y) in SI on the drawing."""
    (x_at, x_edges, x_rows), (y_at, y_edges, y_rows) = _cells(xs, x), _cells(ys, y)
    ax.set_facecolor(NO_RESULT_COLOR)
    shown = np.ma.masked_invalid(z_quantity.display(np.asarray(z, dtype=float)))
    mesh = ax.pcolormesh(x_edges, y_edges, shown, cmap=MAP_COLORMAP, edgecolors="white", linewidth=0.3)
    fig.colorbar(mesh, ax=ax, label=z_quantity.label())
    for rows, values, quantity, set_ticks in ((x_rows, xs, x, ax.set_xticks), (y_rows, ys, y, ax.set_yticks)):
        if rows:
            set_ticks(np.arange(len(values)), [quantity.show(v, 3) for v in values])
    ax.set_xlabel(x.label())
    ax.set_ylabel(y.label())
    return lambda at_x, at_y: (float(np.interp(x.display(at_x), x.display(np.array(xs)), x_at)),
                               float(np.interp(y.display(at_y), y.display(np.array(ys)), y_at)))


def no_result_patch(z: np.ndarray, label: str = "no result (failed run)") -> list[Patch]:
    """The legend entry for grey cells, when there are any."""
    return [Patch(facecolor=NO_RESULT_COLOR, label=label)] if np.isnan(z).any() else []
