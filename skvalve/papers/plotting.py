"""Figure style readable on a laptop screen and atomic PNG writing, shared by the papers' figures.

Every figure is at least :data:`MIN_WIDTH_IN` inches wide, saved at :data:`DPI` dpi, with fonts of at
least :data:`MIN_FONT_PT` points (:data:`STYLE`); figures use the constrained layout, so legends placed
outside the axes get room without cropping. :func:`save_figure` writes to a temporary name in the
target folder and renames it (``os.replace``), so an interrupted run never leaves a truncated PNG under
the final name.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import matplotlib

from ..io.files import replace_atomically

__all__ = ["DPI", "MIN_WIDTH_IN", "MIN_FONT_PT", "STYLE", "readable_style", "save_figure"]

DPI = 150
MIN_WIDTH_IN = 6.0
MIN_FONT_PT = 9.0
STYLE = {
    "font.size": 10.0,
    "axes.titlesize": 10.0,
    "axes.labelsize": 10.0,
    "xtick.labelsize": 9.0,
    "ytick.labelsize": 9.0,
    "legend.fontsize": 9.0,
    "legend.title_fontsize": 9.0,
    "savefig.dpi": DPI,
    "figure.constrained_layout.use": True,
}


@contextlib.contextmanager
def readable_style() -> Iterator[None]:
    """:data:`STYLE` for the figures drawn inside the block (the backend is left as it is: without a
    display matplotlib falls back to Agg by itself)."""
    with matplotlib.rc_context(STYLE):
        yield


def save_figure(fig, path: Path, dpi: int = DPI) -> Path:
    """Write ``fig`` as PNG to ``path`` atomically (temporary file in the same folder, then rename).

    Raises ``ValueError`` when the figure is narrower than :data:`MIN_WIDTH_IN` inches.
    """
    path = Path(path)
    width = fig.get_size_inches()[0]
    if width < MIN_WIDTH_IN:
        raise ValueError(f"figure for {path.name} is {width:.1f} in wide; at least {MIN_WIDTH_IN} in are readable")
    # created by savefig with the umask's permissions (mkstemp would leave it readable by its owner only)
    return replace_atomically(path, lambda temporary: fig.savefig(temporary, format="png", dpi=dpi))
