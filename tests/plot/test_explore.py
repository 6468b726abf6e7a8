"""hovering.explore: the clickable phase portrait, driven by synthetic mouse and key events.

conftest.py selects the headless Agg backend, so the events are built by hand (MouseEvent at the
display coordinates of a data point) and fed to the canvas's callback registry, the way a GUI
backend delivers them.
"""

from __future__ import annotations

import dataclasses
import importlib
import math

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.backend_bases import KeyEvent, MouseEvent, NavigationToolbar2
from matplotlib.colors import to_rgba_array

import hovering
from conftest import PAPER  # hovering.paper.FIGURE
from hovering import Region, Status
from hovering.explore import COLORS, DEFAULT_N_STEPS, Explorer, default_K_range, main
from hovering.plot.style import REGION_COLORS

# The explorer driven as a user drives it (figure, clicks, keys, orbits computed): end to end.
pytestmark = pytest.mark.e2e


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture
def tmap():
    return hovering.TruncatedMap(eps=0.3, **PAPER)


def _system(eps=-0.05):
    return hovering.StepSystem(
        V1=hovering.Harmonic(omega=1.0),
        V2=hovering.Tan(omega=1.4, alpha=0.7),
        coupling=hovering.Bilinear(),
        eps=eps,
        qw1=-1.0,
        qw2=-0.5,
        geometry="step",
    )


@pytest.fixture(scope="module")
def fmap():
    return hovering.FlowMap(_system(), h=1.0, rtol=1e-8)


def click(ex, phi, K, button=1, dblclick=False):
    """Press a mouse button at the data point (phi, K) of the explorer's axes."""
    ex.fig.canvas.draw()  # the layout fixes the axes' position, hence transData
    x, y = ex.ax.transData.transform((phi, K))
    ev = MouseEvent("button_press_event", ex.fig.canvas, x, y, button=button, dblclick=dblclick)
    ex.fig.canvas.callbacks.process(ev.name, ev)
    return ev


def press(ex, key):
    ev = KeyEvent("key_press_event", ex.fig.canvas, key)
    ex.fig.canvas.callbacks.process(ev.name, ev)


def expected_colors(regions):
    return to_rgba_array([COLORS[Region(int(r))] for r in regions])


def check_orbit_matches_map(ex, o, phi, K):
    """The orbit starts at the clicked point, is map.iterate's orbit from it, and is drawn in its
    regions' colours."""
    assert abs(o.phi[0] - phi) < 1e-12 and abs(o.K[0] - K) < 1e-12  # data -> display -> data round trip
    res = ex.map.iterate(o.phi0, o.K0, ex.n_steps, record=("orbit", "regions"))
    n = int(res.steps_done[0])
    assert o.steps_done == n and o.status == Status(int(res.status[0]))
    np.testing.assert_array_equal(o.phi, res.phi[0, : n + 1])
    np.testing.assert_array_equal(o.K, res.K[0, : n + 1])
    np.testing.assert_array_equal(o.region, res.region[0, :n])
    scatter = o.artists[0]
    assert scatter in ex.ax.collections
    np.testing.assert_array_equal(scatter.get_offsets(), np.column_stack([o.phi[:n], o.K[:n]]))
    np.testing.assert_array_equal(scatter.get_facecolors(), expected_colors(o.region))
    start = o.artists[1]
    assert start.get_marker() == "+" and (start.get_xdata()[0], start.get_ydata()[0]) == (o.phi[0], o.K[0])


def test_colors_are_the_plotting_modules():
    for r, c in REGION_COLORS.items():
        assert COLORS[r] == c
    assert Region.MULTI in COLORS


def test_click_launches_an_orbit_of_the_truncated_map_and_right_click_removes_it(tmap):
    ex = hovering.explore(tmap, n_steps=300)
    phi, K = 0.5, -0.1
    click(ex, phi, K)
    assert len(ex.orbits) == 1
    o = ex.orbits[0]
    check_orbit_matches_map(ex, o, phi, K)
    assert len(set(o.region.tolist())) >= 2  # several colours, so the colour check means something
    assert o.status == Status.OK and not o.stopped and "300 steps" in ex.message
    artists = list(o.artists)
    click(ex, -2.0, 0.1, button=3)
    assert ex.orbits == []
    assert all(a not in ex.ax.collections and a not in ex.ax.lines for a in artists)
    ex.close()


def test_click_launches_an_orbit_of_the_flow_map(fmap):
    ex = hovering.explore(fmap, n_steps=40)
    assert ex.ax.get_xlabel() == r"$\phi$" and ex.ax.get_ylabel() == r"$K$"
    phi, K = 0.5, -0.03  # in the default view, an orbit through all four regions
    click(ex, phi, K)
    assert len(ex.orbits) == 1
    o = ex.orbits[0]
    check_orbit_matches_map(ex, o, phi, K)
    assert len(set(o.region.tolist())) >= 2
    click(ex, 0.0, 0.0, button=3)
    assert ex.orbits == []
    ex.close()


def test_flow_map_in_section_coordinates_shows_theta_I_over_its_band():
    fs = hovering.FlowMap(_system(), h=1.0, rtol=1e-8, coordinates="section")
    ex = hovering.explore(fs, n_steps=20)
    assert ex.ax.get_xlabel() == r"$\theta$" and ex.ax.get_ylabel() == r"$I$"
    assert ex.K_range == fs.valid_band() and ex.ax.get_ylim() == fs.valid_band()
    click(ex, 0.3, 0.2)
    check_orbit_matches_map(ex, ex.orbits[0], 0.3, 0.2)
    ex.close()


def test_truncated_family(tmap):
    Kg = np.concatenate([-(np.linspace(3.0, 0.0, 61) ** 2) / 3.0, np.linspace(0.05, 1.0, 20)])
    fam = hovering.TruncatedFamily.from_map(tmap, Kg, forcing=(1.0, -0.2))
    ex = hovering.explore(fam, n_steps=200)
    assert ex.n_steps == 200
    click(ex, 0.4, -0.15)
    check_orbit_matches_map(ex, ex.orbits[0], 0.4, -0.15)
    ex.close()


def test_clicks_outside_the_axes_double_clicks_middle_clicks_and_toolbar_modes_add_nothing(tmap):
    ex = hovering.explore(tmap, n_steps=50)
    ex.fig.canvas.draw()
    before = ex.message
    for xy in ((1.0, 1.0), (ex.fig.bbox.width - 2, ex.fig.bbox.height - 2)):  # figure corners
        ev = MouseEvent("button_press_event", ex.fig.canvas, *xy, button=1)
        assert ev.inaxes is None
        ex.fig.canvas.callbacks.process(ev.name, ev)
    click(ex, 0.5, -0.1, dblclick=True)
    click(ex, 0.5, -0.1, button=2)
    assert ex.orbits == [] and ex.message == before
    tb = NavigationToolbar2(ex.fig.canvas)
    tb.zoom()  # zoom mode: the click is the toolbar's
    click(ex, 0.5, -0.1)
    click(ex, 0.5, -0.1, button=3)
    assert ex.orbits == []
    tb.zoom()  # off again
    click(ex, 0.5, -0.1)
    assert len(ex.orbits) == 1
    ex.close()


def test_clicks_in_other_axes_of_the_figure_add_nothing_and_close_keeps_a_figure_it_did_not_make(tmap):
    fig, (a0, a1) = plt.subplots(1, 2)
    ex = hovering.explore(tmap, n_steps=50, ax=a0)
    fig.canvas.draw()
    x, y = a1.transData.transform((0.5, 0.5))
    ev = MouseEvent("button_press_event", fig.canvas, x, y, button=1)
    assert ev.inaxes is a1
    fig.canvas.callbacks.process(ev.name, ev)
    assert ex.orbits == []
    ex.close()
    assert plt.fignum_exists(fig.number)


def test_off_section_click_adds_no_orbit_and_says_so(fmap):
    # Decision: a point where the map has no point (OFF_SECTION before any return) is not an orbit;
    # nothing is drawn, launch returns None and the title says why.
    ex = hovering.explore(fmap, n_steps=20, K_range=(-0.45, 0.05))
    assert fmap.valid_band()[0] > -0.45  # the shaded part below the band is in view
    n_artists = len(ex.ax.collections) + len(ex.ax.lines)
    click(ex, 0.3, -0.42)
    assert ex.orbits == []
    assert "OFF_SECTION" in ex.message and "Sigma_h" in ex.message
    assert "OFF_SECTION" in ex.ax.get_title(loc="left")
    assert len(ex.ax.collections) + len(ex.ax.lines) == n_artists
    assert ex.launch(0.3, -0.42) is None
    ex.close()


def test_click_below_the_truncated_band_adds_no_orbit(tmap):
    ex = hovering.explore(tmap, n_steps=20, K_range=(-3.5, 0.5))
    click(ex, 0.3, -3.3)
    assert ex.orbits == [] and "ESCAPED" in ex.message and "outside the band" in ex.message
    ex.close()


def test_orbit_that_escapes_is_drawn_up_to_where_it_stopped(tmap):
    lo = tmap.valid_band()[0]
    phi = np.linspace(-np.pi, np.pi, 64, endpoint=False)
    res = tmap.iterate(phi, lo + 0.05, 50, record=())
    i = int(np.flatnonzero((res.status == Status.ESCAPED) & (res.steps_done >= 2))[0])
    ex = hovering.explore(tmap, n_steps=50, K_range=(-3.5, 0.5))
    o = ex.launch(phi[i], lo + 0.05)
    n = o.steps_done
    assert o.stopped and o.status == Status.ESCAPED and 2 <= n < 50
    check_orbit_matches_map(ex, o, phi[i], lo + 0.05)
    assert o.K[n] < lo  # the image outside the band
    stop = o.artists[-1]
    assert stop.get_marker() == "x" and (stop.get_xdata()[0], stop.get_ydata()[0]) == (o.phi[n], o.K[n])
    assert "ESCAPED" in ex.message and f"after {n} of 50" in ex.message
    legend = [t.get_text() for t in ex.ax.get_legend().get_texts()]
    assert f"#{o.number}: ESCAPED after {n}" in legend
    assert ex.ax.get_ylim() == (-3.5, 0.5)  # the escaped point did not move the view
    ex.close()


def test_interrupted_orbit_is_drawn_and_the_interrupt_propagates():
    class Interrupting(hovering.TruncatedMap):
        """Stops every iteration after 7 steps the way Ctrl-C does: KeyboardInterrupt with .partial."""

        def iterate(self, *args, **kwargs):
            res = super().iterate(*args, **kwargs)
            phi, K, reg = res.phi.copy(), res.K.copy(), res.region.copy()
            phi[:, 8:], K[:, 8:], reg[:, 7:] = np.nan, np.nan, int(Region.NONE)
            exc = KeyboardInterrupt("interrupted")
            exc.partial = dataclasses.replace(
                res,
                phi=phi,
                K=K,
                region=reg,
                steps_done=np.array([7]),
                status=np.array([int(Status.INTERRUPTED)], dtype=np.int8),
            )
            raise exc

    ex = hovering.explore(Interrupting(eps=0.3, **PAPER), n_steps=100)
    with pytest.raises(KeyboardInterrupt):
        ex.launch(0.5, -0.1)
    (o,) = ex.orbits
    assert o.status == Status.INTERRUPTED and o.steps_done == 7 and o.phi.shape == (8,)
    assert "INTERRUPTED" in ex.message
    ex.close()


def test_keys_remove_the_last_orbit_and_clear(tmap):
    ex = hovering.explore(tmap, n_steps=30)
    for K in (-0.3, -0.2, -0.1):
        click(ex, 0.5, K)
    assert [o.number for o in ex.orbits] == [1, 2, 3]
    press(ex, "u")
    assert [o.number for o in ex.orbits] == [1, 2]
    press(ex, "delete")
    assert [o.number for o in ex.orbits] == [1]
    click(ex, 0.5, 0.1)
    press(ex, "a")  # other keys do nothing
    assert [o.number for o in ex.orbits] == [1, 4]
    press(ex, "x")
    assert ex.orbits == [] and "cleared 2" in ex.message
    assert len(ex.ax.collections) == 0  # every orbit's scatter is gone
    click(ex, 0.5, 0.1, button=3)  # nothing left to remove: a message, no error
    assert ex.message == "no orbit to remove"
    ex.close()


def test_close_stops_listening_and_closes_the_figure(tmap):
    ex = hovering.explore(tmap, n_steps=30)
    click(ex, 0.5, -0.1)
    fig = ex.fig
    ex.fig.canvas.draw()
    x, y = ex.ax.transData.transform((0.5, -0.2))
    ex.close()
    assert not plt.fignum_exists(fig.number)
    ev = MouseEvent("button_press_event", fig.canvas, x, y, button=1)
    fig.canvas.callbacks.process(ev.name, ev)
    assert len(ex.orbits) == 1
    ex.close()  # twice is harmless


def test_long_orbits_are_thinned_for_drawing_only(tmap):
    ex = hovering.explore(tmap, n_steps=1000, max_points=100)
    o = ex.launch(0.5, -0.1)
    assert o.phi.shape == (1001,) and len(o.artists[0].get_offsets()) == 100
    np.testing.assert_array_equal(o.artists[0].get_offsets()[:, 0], o.phi[:1000:10])
    ex.close()


def test_default_n_steps_depend_on_the_map(tmap, fmap):
    assert hovering.explore(tmap).n_steps == 2000 == DEFAULT_N_STEPS["truncated"]
    assert hovering.explore(fmap).n_steps == 500 == DEFAULT_N_STEPS["flow"]


def test_default_K_range(tmap, fmap):
    th = tmap.theory()
    s = abs(tmap.eps) / abs(math.sin(tmap.Omega0 / 2))
    assert th.hovers and default_K_range(tmap) == pytest.approx((2 * th.K_crit, s), rel=1e-14)
    assert Explorer(tmap).ax.get_ylim() == pytest.approx((2 * th.K_crit, s), rel=1e-14)
    assert default_K_range(tmap.with_eps(-0.3)) == pytest.approx((-2 * s, s), rel=1e-14)  # no hovering
    assert default_K_range(tmap.with_eps(0.0)) == (-1.0, 0.5)
    lo, hi = default_K_range(fmap)
    band = fmap.valid_band()
    assert band[0] <= lo < fmap.theory().K_crit < 0 < hi <= band[1]
    assert lo == pytest.approx(2 * fmap.theory().K_crit, rel=1e-14)


@pytest.mark.parametrize("bad", [0, 10**7 + 1, -5, 2.5, True, "100", np.float64(3.0)])
def test_bad_n_steps_is_a_value_error_naming_it(tmap, bad):
    figs = plt.get_fignums()
    with pytest.raises(ValueError, match=r"n_steps must be an integer in \[1, 10000000\]"):
        hovering.explore(tmap, n_steps=bad)
    assert plt.get_fignums() == figs  # refused before any figure was made


@pytest.mark.parametrize(
    "kw, name",
    [
        (dict(K_range=(0.1, -0.1)), "K_range"),
        (dict(K_range=(float("nan"), 0.1)), "K_range"),
        (dict(K_range=(0.0, 1.0, 2.0)), "K_range"),
        (dict(K_range="ab"), "K_range"),
        (dict(K_range=(0.0, "1")), "K_range"),
        (dict(marker_size=0.0), "marker_size"),
        (dict(max_points=0), "max_points"),
        (dict(ax="axes"), "ax"),
    ],
)
def test_bad_options_are_value_errors_naming_them(tmap, kw, name):
    figs = plt.get_fignums()
    with pytest.raises(ValueError, match=name):
        hovering.explore(tmap, **kw)
    assert plt.get_fignums() == figs


@pytest.mark.parametrize("bad", [3, None, object(), np.zeros(3)])
def test_not_a_map_is_a_value_error(bad):
    with pytest.raises(ValueError, match="map_or_scene"):
        hovering.explore(bad)


def test_bad_launch_points_are_value_errors(tmap):
    ex = hovering.explore(tmap, n_steps=10)
    for phi, K, name in ((float("nan"), 0.0, "phi"), (0.0, float("inf"), "K"), (1e7, 0.0, "phi"), ("1", 0.0, "phi")):
        with pytest.raises(ValueError, match=name):
            ex.launch(phi, K)
    assert ex.orbits == []
    ex.close()


def _scene(tmp_path, text):
    p = tmp_path / "scene.toml"
    p.write_text(text.replace("OUT", str(tmp_path / "fig.png")))
    return p


PORTRAIT = """
kind = "portrait"
output = "OUT"
n_steps = 100
K0_range = [-0.5, 0.2]
[map]
Omega0 = "OMEGA_G"
theta_w = "3*pi/4"
[[panels]]
id = "a"
eps = 0.2
[[panels]]
id = "b"
eps = -0.2
"""


def test_a_scene_path_explores_its_first_panels_map(tmp_path):
    p = _scene(tmp_path, PORTRAIT)
    for path in (p, str(p)):
        ex = hovering.explore(path, n_steps=20)
        assert isinstance(ex.map, hovering.TruncatedMap)
        assert ex.map.eps == 0.2 and ex.map.Omega0 == hovering.OMEGA_G and ex.map.theta_w == 3 * np.pi / 4
        click(ex, 0.5, -0.1)
        check_orbit_matches_map(ex, ex.orbits[0], 0.5, -0.1)
        ex.close()
    assert not (tmp_path / "fig.png").exists()


def test_a_hovering_area_scene_explores_its_first_series_at_its_first_eps(tmp_path):
    p = _scene(
        tmp_path,
        """
kind = "hovering_area"
output = "OUT"
n_steps = 100
eps = [0.15, 0.3]
[[series]]
label = "a"
Omega0 = 2.0
theta_w = 2.5
""",
    )
    m = hovering.explore(p).map
    assert (m.eps, m.Omega0, m.theta_w) == (0.15, 2.0, 2.5)


def test_bad_scenes(tmp_path):
    with pytest.raises(FileNotFoundError):
        hovering.explore(tmp_path / "missing.toml")
    with pytest.raises(ValueError, match="n_steps"):
        hovering.explore(_scene(tmp_path, PORTRAIT.replace("n_steps = 100", "n_steps = 0")))


def test_main_on_a_headless_backend_checks_everything_shows_nothing_and_says_why(tmp_path, capsys):
    p = _scene(tmp_path, PORTRAIT)
    figs = plt.get_fignums()
    assert main([str(p), "--n-steps", "10", "--K-range", "-0.5", "0.3"]) == 0
    err = capsys.readouterr().err
    assert "cannot open a window" in err and "MPLBACKEND" in err
    assert plt.get_fignums() == figs
    assert sorted(f.name for f in tmp_path.iterdir()) == ["scene.toml"]  # nothing written


def test_main_errors(tmp_path, capsys):
    p = _scene(tmp_path, PORTRAIT)
    assert main([str(tmp_path / "missing.toml")]) == 2
    assert "error" in capsys.readouterr().err
    assert main([str(p), "--K-range", "0.3", "-0.5"]) == 2
    assert "K_range must be increasing" in capsys.readouterr().err
    for bad in ("0", "1e3", "10000001", "x"):
        with pytest.raises(SystemExit) as e:
            main([str(p), "--n-steps", bad])
        assert e.value.code == 2
        assert "--n-steps" in capsys.readouterr().err
    assert plt.get_fignums() == []


def test_backend_detection(monkeypatch):
    import matplotlib

    mod = importlib.import_module("hovering.explore")  # hovering.explore itself is the function
    assert not mod._backend_is_interactive()  # conftest's Agg
    for name, interactive in (("TkAgg", True), ("QtAgg", True), ("WebAgg", True), ("pdf", False), ("svg", False)):
        monkeypatch.setattr(matplotlib, "get_backend", lambda name=name: name)
        assert mod._backend_is_interactive() is interactive, name


def test_main_with_a_window_shows_the_explorer_until_it_is_closed(tmp_path, monkeypatch, capsys):
    mod = importlib.import_module("hovering.explore")
    shown = []

    def show():
        # What a user does in the window: click once, then close it.
        (num,) = plt.get_fignums()
        fig = plt.figure(num)
        ax = fig.axes[0]
        fig.canvas.draw()
        x, y = ax.transData.transform((0.5, -0.1))
        ev = MouseEvent("button_press_event", fig.canvas, x, y, button=1)
        fig.canvas.callbacks.process(ev.name, ev)
        shown.append(ax.get_title(loc="left"))
        plt.close(fig)

    monkeypatch.setattr(mod, "_backend_is_interactive", lambda: True)
    monkeypatch.setattr(plt, "show", show)
    assert main([str(_scene(tmp_path, PORTRAIT)), "--n-steps", "25"]) == 0
    assert len(shown) == 1 and shown[0].startswith("#1 from (0.5, -0.1") and "25 steps" in shown[0]
    assert "Left click: launch" in capsys.readouterr().out
