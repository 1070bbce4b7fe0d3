"""The studies' charts: matplotlib (the ``studies`` extra) on its Agg backend, and a figure written as a PNG."""
from __future__ import annotations

import os

from ...support import require

__all__ = ["pyplot", "save"]


def pyplot(what: str):
    """``matplotlib.pyplot`` on the Agg backend (no display needed); MissingDependencyError, naming the ``studies``
    extra and ``what`` needs it, where matplotlib is not installed."""
    require("matplotlib", "studies", what).use("Agg")
    return require("matplotlib.pyplot", "studies", what)


def save(fig, path: str, dpi: int = 110, rect=None) -> str:
    """Lay ``fig`` out (within ``rect`` of the figure, when given), write it to ``path`` as a PNG of ``dpi`` (its
    folder made where missing) and close it; returns ``path``."""
    fig.tight_layout(**({} if rect is None else {"rect": rect}))
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=dpi)
    pyplot("a chart").close(fig)
    return path
