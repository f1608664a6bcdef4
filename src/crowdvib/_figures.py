"""What every figure shares: matplotlib on first use, axes and panels, saving and embedding.

The base of the figures of every layer (the ``plots`` modules of ``signals``, ``response`` and
``identification``, ``reporting``'s design figures), so that a result's ``plot()`` draws
without importing a layer above its own. This and the plotting modules are the only ones that
import matplotlib, and only when a plot is asked for; no figure function calls ``plt.show()``.
"""

from dataclasses import dataclass

import numpy as np
from ._files import atomic_path
from .errors import ParameterError

__all__ = ["FigureAxes", "save_figure", "figure_bytes", "pyplot", "axes_or_new", "in_band", "panels",
           "positive_or_nan", "DARK", "LIGHT"]

# The paper's figures are black and gray; a colour-blind-safe dark/light pair keeps them legible
# on screen and in a grayscale print.
DARK, LIGHT = "black", "0.6"


@dataclass(frozen=True)
class FigureAxes:
    """The figure and axes of a multi-panel plot.

    Attributes
    ----------
    figure : matplotlib.figure.Figure
    axes : tuple of matplotlib.axes.Axes
        The panels, in reading order (left to right, top to bottom).
    """

    figure: object
    axes: tuple


def pyplot():
    import matplotlib

    # A library must not pop up windows or need a display; Agg renders anywhere. force=False
    # keeps a backend the caller chose before importing pyplot.
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def axes_or_new(ax, figsize=(7.5, 4.2)):
    if ax is not None:
        return ax
    _, ax = pyplot().subplots(figsize=figsize, layout="constrained")
    return ax


def in_band(frequency, band):
    """Index of the frequencies within [lower, upper] [Hz]; everything for band None."""
    if band is None:
        return slice(None)
    return (frequency >= band[0]) & (frequency <= band[1])


def panels(axes, nrows, ncols, figsize, **options):
    """Given panels (checked for their number) or a new figure of nrows × ncols."""
    if axes is not None:
        axes = tuple(np.ravel(axes))
        if len(axes) != nrows * ncols:

            raise ParameterError(f"axes must hold {nrows * ncols} panels, got {len(axes)}")
        return FigureAxes(axes[0].figure, axes)
    figure, grid = pyplot().subplots(nrows, ncols, figsize=figsize, layout="constrained",
                                      squeeze=False, **options)
    return FigureAxes(figure, tuple(grid.ravel()))


def positive_or_nan(values):
    """Values with non-positive entries as NaN: a log axis would otherwise drop or warn."""
    values = np.asarray(values, dtype=float)
    return np.where(values > 0, values, np.nan)


def save_figure(ax, path):
    """Write the figure of ``ax`` to ``path`` (format from the suffix) atomically, and close it.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or FigureAxes
        Any object with a ``figure``.
    path : str or pathlib.Path
        Target file; ``.png``, ``.svg`` and ``.pdf`` are the useful suffixes.

    Returns
    -------
    path
    """
    import matplotlib.pyplot as plt


    figure = ax.figure
    with atomic_path(path) as temporary:
        figure.savefig(temporary, format=str(path).rsplit(".", 1)[-1], dpi=130)
    plt.close(figure)
    return path


def figure_bytes(ax, format="png", *, dpi=110):
    """The figure of ``ax`` encoded as PNG or SVG bytes, and the figure closed.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or FigureAxes
    format : {"png", "svg"}
    dpi : float
        Resolution of a PNG [dots per inch].

    Returns
    -------
    bytes
    """
    import io

    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    # A fixed date and no hash salt keep an SVG byte-identical between runs of the same data.
    metadata = {"Date": None} if format == "svg" else {"Software": None}
    ax.figure.savefig(buffer, format=format, dpi=dpi, metadata=metadata)
    plt.close(ax.figure)
    return buffer.getvalue()
