"""What a figure draws, as data: for comparing a redrawn figure with the original."""

from __future__ import annotations

import numpy as np


def artists(fig) -> dict:
    """Every drawn data array of a figure, keyed by axes index, artist kind and order."""
    data = {}
    for i, ax in enumerate(fig.axes):
        for j, ln in enumerate(ax.lines):
            x, y = ln.get_data()
            data[(i, "line", j, ln.get_gid(), ln.get_label())] = (np.asarray(x, float), np.asarray(y, float))
        for j, c in enumerate(ax.collections):
            data[(i, "coll", j, c.get_gid(), c.get_label())] = (
                np.asarray(c.get_offsets(), float),
                np.asarray(c.get_facecolor(), float),
            )
        data[(i, "axes")] = (ax.get_xlabel(), ax.get_ylabel(), ax.get_title(), ax.get_xlim(), ax.get_ylim())
    return data
