"""Old path of :func:`hovering.pipeline.phase_portrait` and the drawing primitives (deprecated;
removed in 0.4.0)."""

from ._deprecated import moved_module

__getattr__ = moved_module(
    __name__, "hovering.pipeline", {"plot_orbits": "hovering.plot.primitives", "REGION_COLORS": "hovering._style"}
)
