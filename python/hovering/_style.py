"""Colours, line styles and legend texts: the one place both the computing and the drawing side
read them (a scene's result stores colour names; the figures turn them into artists). Data only
(no matplotlib), so the computing side reads it without depending on the drawing side."""

from __future__ import annotations

from ._enums import Region

__all__ = [
    "REGION_COLORS",
    "REGION_LABELS",
    "SPECIAL_COLORS",
    "SPECIAL_LABELS",
    "CORNER_STYLES",
    "GEOMETRY_COLOR",
    "WALL_REGION_COLORS",
    "CORNER_COLORS",
    "orbit_color",
    "QUICK_MARK",
]

#: Colour of each region in region-coloured plots (J_0u, J_0, J_1, J_R, and two or more impacts).
REGION_COLORS = {
    Region.BESIDE: "#4c72b0",
    Region.ABOVE: "#55a868",
    Region.UPPER: "#dd8452",
    Region.RIGHT: "#c44e52",
    Region.MULTI: "#8172b3",
}

#: Legend text of each region.
REGION_LABELS = {r: f"J_{r.label}" if r != Region.MULTI else "2+ impacts" for r in REGION_COLORS}

#: Colours of the paper's special orbits (matplotlib's default cycle, as in the paper).
SPECIAL_COLORS = {"blue": "C0", "orange": "C1", "green": "C2", "red": "C3"}

#: Legend text of the special orbits' starts (sec:truncatedmapnumact).
SPECIAL_LABELS = {
    "blue": r"L1, $K_0=\tilde K_c$",
    "orange": r"L1, $K_0=\tilde K_c+0.05|\varepsilon|$",
    "green": r"L1, $K_0=0$",
    "red": r"L2, $K_0=0$",
}

#: The paper's region colours of the wall-section figures (fig:wallsection: J_R yellow, J_0 gray,
#: J_1 cyan; J_0u, outside the wall's tangency line, pale blue; two or more impacts as elsewhere).
WALL_REGION_COLORS = {
    Region.RIGHT: "#f2c200",
    Region.ABOVE: "#9a9a9a",
    Region.UPPER: "#00d5e0",
    Region.BESIDE: "#dce9f5",
    Region.MULTI: "#8172b3",
}

#: Colour of each incoming direction of the corner and its corner-singularity curve (the paper's
#: fig:corner_directions: p_R0 red, p_01 blue, p_1R green).
CORNER_COLORS = {"R0": "#d0021b", "01": "#0515c6", "1R": "#417505"}

#: Line style of each corner-singularity curve phi_ab (dashed black family).
CORNER_STYLES = {"01": ":", "1R": "--", "R0": "-."}

#: Grey of K = 0, L1, L2 and the step's walls.
GEOMETRY_COLOR = "0.55"

#: Orbit classes (hovering.classify_orbits) in the impact-zone figure.
CLASS_COLORS = {"circle": "#1f77b4", "islands": "#2ca02c", "chaotic": "#d62728", "undecided": "#9a9a9a"}

#: Title suffix of a quick run.
QUICK_MARK = " [quick]"


def orbit_color(i: int, offset: int = 0) -> str:
    """The i-th colour of matplotlib's default cycle (shifted by ``offset``).

    Parameters
    ----------
    i : int
        Orbit index.
    offset : int, optional
        First colour used.

    Returns
    -------
    str
        ``"C0"`` .. ``"C9"``.
    """
    return f"C{(i + offset) % 10}"
