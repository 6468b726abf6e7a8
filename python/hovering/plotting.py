"""Phase portraits of the truncated map (matplotlib; works headless with the Agg backend)."""

from __future__ import annotations


import numpy as np

from ._common import Region

__all__ = ["REGION_COLORS", "draw_geometry", "plot_orbits", "phase_portrait"]

#: Colour of each region in region-coloured plots.
REGION_COLORS = {
    Region.BESIDE: "#4c72b0",
    Region.ABOVE: "#55a868",
    Region.UPPER: "#dd8452",
    Region.RIGHT: "#c44e52",
}


def draw_geometry(ax, m, K_range, corner_curves=True, lines=True, n=400):
    """Draw the tangency circle K = 0, the lines L1, L2 and the corner-singularity curves.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    m : TruncatedMap
        The map whose geometry is drawn.
    K_range : tuple of float
        ``(K_low, K_high)`` of the plot.
    corner_curves : bool, optional
        Draw ``phi_01, phi_1R, phi_R0`` for K < 0 (dashed).
    lines : bool, optional
        Draw K = 0, L1 and L2 (grey).
    n : int, optional
        Samples per curve.

    Returns
    -------
    list
        The artists added.
    """
    lo, hi = m.valid_band()
    K = np.linspace(max(K_range[0], lo * (1 - 1e-9)), K_range[1], n)
    artists = []
    if lines:
        artists.append(ax.axhline(0.0, color="0.55", lw=0.8, zorder=1))
        for fn, name in ((m.L1, "L1"), (m.L2, "L2")):
            phi = fn(K)
            artists += ax.plot(_break(phi), K, color="0.55", lw=0.8, ls="-", zorder=1, label=name)
    if corner_curves:
        Kn = K[K < 0]
        if Kn.size:
            for key, style in (("01", ":"), ("1R", "--"), ("R0", "-.")):
                phi = m.corner_curves(Kn)[key]
                artists += ax.plot(_break(phi), Kn, color="k", lw=0.8, ls=style, zorder=2, label=f"phi_{key}")
    return artists


def _break(phi):
    """Insert NaN where a wrapped curve jumps across phi = +-pi, so lines are not drawn across."""
    phi = np.array(phi, dtype=float)
    jumps = np.abs(np.diff(phi)) > np.pi
    phi[1:][jumps] = np.nan
    return phi


def plot_orbits(ax, res, color_by="region", s=0.05, max_points=2_000_000, colors=None):
    """Scatter recorded orbits of an :class:`~hovering.IterateResult`.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Target axes.
    res : IterateResult
        Result with ``"orbit"`` recorded (and ``"regions"`` for ``color_by="region"``).
    color_by : {"region", "orbit"}, optional
        Colour each point by the region it lies in, or each orbit by its own colour.
    s : float, optional
        Marker size.
    max_points : int, optional
        Thin each orbit uniformly so that at most this many points are drawn in all.
    colors : sequence, optional
        Per-orbit colours for ``color_by="orbit"``.

    Returns
    -------
    list
        One PathCollection per orbit (``color_by="orbit"``) or per region.
    """
    if res.phi is None:
        raise ValueError("plot_orbits needs a result with record='orbit'")
    n_orb, n_pts = res.phi.shape
    stride = max(1, int(np.ceil(n_orb * n_pts / max_points)))
    phi, K = res.phi[:, ::stride], res.K[:, ::stride]
    out = []
    if color_by == "region":
        if res.region is None:
            raise ValueError("color_by='region' needs a result with record='regions'")
        reg = np.full(res.phi.shape, -1, dtype=np.int8)
        reg[:, :-1] = res.region
        reg = reg[:, ::stride]
        for r, c in REGION_COLORS.items():
            sel = reg == int(r)
            if sel.any():
                out.append(ax.scatter(phi[sel], K[sel], s=s, c=c, lw=0, rasterized=True, label=f"J_{r.label}"))
    elif color_by == "orbit":
        cmap = colors if colors is not None else [f"C{i % 10}" for i in range(n_orb)]
        for i in range(n_orb):
            ok = np.isfinite(phi[i])
            out.append(ax.scatter(phi[i, ok], K[i, ok], s=s, color=cmap[i], lw=0, rasterized=True))
    else:
        raise ValueError(f"color_by must be 'region' or 'orbit', got {color_by!r}")
    return out


def phase_portrait(m, n_orbits=30, n_steps=20_000, K_range=(-1.2, 0.6), ax=None, color_by="region", title=None):
    """Iterate orbits started evenly along L1 and draw them with the map's geometry.

    This is the construction of the paper's fig:smallepsmany.

    Parameters
    ----------
    m : TruncatedMap
        The map.
    n_orbits : int, optional
        Initial conditions, evenly spaced in K on L1.
    n_steps : int, optional
        Iterates per orbit.
    K_range : tuple of float, optional
        Range of initial K (and of the plot, padded).
    ax : matplotlib.axes.Axes, optional
        Target axes; a new figure is made if omitted.
    color_by : {"region", "orbit"}, optional
        See :func:`plot_orbits`.
    title : str, optional
        Axes title (default: the parameters).

    Returns
    -------
    ax : matplotlib.axes.Axes
    res : IterateResult
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(8, 5))
    K0 = np.linspace(K_range[0], K_range[1], n_orbits)
    res = m.iterate(m.L1(K0), K0, n_steps, record=("orbit", "regions", "rotation"))
    plot_orbits(ax, res, color_by=color_by)
    pad = 0.1 * (K_range[1] - K_range[0])
    draw_geometry(ax, m, (K_range[0] - pad, K_range[1] + pad))
    ax.set_xlim(-np.pi, np.pi)
    ax.set_ylim(K_range[0] - pad, K_range[1] + pad)
    ax.set_xlabel(r"$\phi$")
    ax.set_ylabel(r"$K$")
    if title is None:
        title = (
            rf"$\varepsilon={m.eps:g},\ \Omega_0={m.Omega0:.4f},\ \theta_w={m.theta_w:.4f},\ "
            rf"\tau_0={m.tau0:g},\ \tau_1={m.tau1:g},\ \lambda={m.lam:g}$"
        )
    ax.set_title(title, fontsize=9)
    if color_by == "region":
        ax.legend(loc="upper right", markerscale=40, fontsize=7, framealpha=0.8)
    return ax, res
