"""The figure of the ``impact_zone`` kind: does anything cross the impact zone? The flow (left) and
its model (right): the scan's orbits in the zone coordinate, each start's range of levels, barriers
and the transit statistics.
"""

from __future__ import annotations

import numpy as np

from ..._style import CLASS_COLORS, GEOMETRY_COLOR
from ...scenes.results import ImpactZoneResult
from ...scenes.spec import figure_inches
from ..common import draws, grid, quick_mark, system_text

__all__ = ["impact_zone_figure"]


def _transit_text(study) -> str:
    lines = []
    for d, t in (("up", study.up), ("down", study.down)):
        k = int(np.count_nonzero(t.crossed))
        reach = np.nanmax(t.s_max) if d == "up" else np.nanmin(t.s_min)
        rate = t.escape_rate
        lines.append(
            f"{d}: {k}/{t.crossed.size} crossed s={t.start_s:g}->{t.target_s:g} in {t.n_steps:,} returns; "
            f"{'highest' if d == 'up' else 'lowest'} s reached {reach:.3f}"
            + (f"; rate {rate[0]:.2g}+-{rate[1]:.1g}/return" if rate is not None else "")
        )
    return "\n".join(lines)


@draws("impact_zone")
def impact_zone_figure(result: ImpactZoneResult):
    """Does anything cross the impact zone? The flow (left) and its model (right).

    Top: the scan's orbits in the zone coordinate s (0 on the floor, 1 on the critical curve),
    coloured by class (circle, islands, chaotic, undecided); the levels where a two-sided barrier
    crosses the scan's line are dashed. Bottom: for each start (its level s0 on the line), the
    range of s its orbit visited, in the class colour; barriers dashed; the transit statistics.

    Parameters
    ----------
    result : ImpactZoneResult
        The computed scene.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scene, q = result.scene, quick_mark(result)
    fig, axes = grid(4, (2, 2), figure_inches(scene))
    for col, study in enumerate((result.flow, result.model)):
        top, bottom = axes[col], axes[2 + col]
        sc, zone = study.scan, study.zone
        title = "full return map (flow)" if col == 0 else f"truncated model ({result.model_name} forcing)"
        for kind, color in CLASS_COLORS.items():
            rows = np.flatnonzero(sc.kind == kind)
            if sc.phi is not None and rows.size:
                P, Kk = sc.phi[rows].ravel(), sc.K[rows].ravel()
                ok = np.isfinite(P) & np.isfinite(Kk)
                top.scatter(
                    P[ok], zone.s(P[ok], Kk[ok]), s=0.3, color=color, rasterized=True, label=f"{kind} ({rows.size})"
                ).set_gid(f"class:{kind}")
            if rows.size:
                bottom.vlines(sc.s0[rows], sc.s_min[rows], sc.s_max[rows], color=color, lw=2).set_gid(f"range:{kind}")
        for ax in (top, bottom):
            for b in sc.barriers:
                (top if ax is top else bottom).axhline(b, color="k", ls="--", lw=0.7, gid="barrier")
            ax.axhline(0.0, color=GEOMETRY_COLOR, lw=1.0, gid="floor")
            ax.axhline(1.0, color="k", lw=1.0, gid="ceiling")
        for b in sc.barriers:
            bottom.axvline(b, color="k", ls=":", lw=0.5)
        bottom.plot([0, 1], [0, 1], color=GEOMETRY_COLOR, lw=0.5)
        top.set_xlim(-np.pi, np.pi)
        top.set_ylim(-0.1, 1.1)
        top.set_xlabel(r"$\phi$")
        top.set_ylabel(r"zone coordinate $s$ (floor 0, critical curve 1)")
        top.set_title(
            f"({'ab'[col]}) {title}: {len(sc)} orbits on {sc.line}, {sc.n_steps:,} returns; "
            f"{int(sc.barrier.sum())} barrier(s), {len(sc.layers)} layer(s){q}",
            fontsize=8,
        )
        top.legend(loc="upper right", fontsize=7, markerscale=12)
        bottom.set_xlim(0, 1)
        bottom.set_ylim(-0.1, 1.1)
        bottom.set_xlabel(f"start level $s_0$ on {sc.line}")
        bottom.set_ylabel("levels visited by the orbit")
        bottom.set_title(
            f"({'cd'[col]}) layers; no orbit spans s 0.1..0.9: {sc.spanning(0.1, 0.9).size == 0}", fontsize=8
        )
        bottom.text(0.02, 0.98, _transit_text(study), transform=bottom.transAxes, fontsize=7, va="top", gid="transit")
    fig.suptitle(
        scene.title
        + "\n"
        + system_text(scene, result)
        + f"; the model acts with eps b1 = {scene.system.eps * result.b1:.4g}",
        fontsize=9,
    )
    return fig
