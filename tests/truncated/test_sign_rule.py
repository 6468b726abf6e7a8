"""The sign of eps that hovers is sign(sin(Omega0/2) b_1), for every Omega0 (period 4 pi, not 2 pi),
checked against the truncated model itself; the theory's tolerance for vanishing modes and its
statements for the wall and no-wall geometries; the docs state the rule in that form."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import hovering as hv

ROOT = Path(__file__).resolve().parents[2]
THETA_W = 3 * math.pi / 4
EPS = 0.05
#: Omega0 / 2 pi: golden-mean-like rotations (no low-order resonance near K = 0 at eps = 0.05) and a
#: few others, in (-1.4, 3.3): negative Omega0, (0, 2 pi), (2 pi, 4 pi) (x in (1, 2)), (4 pi, 6 pi),
#: (6 pi, 8 pi). sin(Omega0/2) = sin(pi x) has |.| >= 0.58 at all of them.
TURNS = (0.381966, 0.618034, 1.381966, 1.618034, 1.1, 1.7, 2.381966, 2.618034, 3.3, 0.3, -0.381966, -1.381966)
K_GRID = np.concatenate([-(np.linspace(1.0, 0.0, 81) ** 2), np.linspace(0.02, 1.0, 30)])


def _model(eps, Omega0, tau0, b1):
    m = hv.TruncatedMap(eps=eps, Omega0=Omega0, theta_w=THETA_W, tau0=tau0, tau1=0.5, lam=0.5)
    return m if b1 == 1.0 else hv.TruncatedFamily.from_map(m, K_GRID, forcing=(b1,))


def _measured_hovering_sign(Omega0, tau0, b1):
    """Which sign of eps hovers, by iterating the model: 8 starts on L1 between the predicted critical
    curve and K = 0 (0.1 .. 0.8 of eq:kcrit's depth |eps b1| (1 - cos theta_w) / (2 |sin(Omega0/2)|)),
    20,000 steps each, stopped at the first impact. +1 if for eps > 0 none impacts and for eps < 0
    all do, -1 for the reverse, 0 otherwise."""
    depth = abs(EPS * b1) * (1 - math.cos(THETA_W)) / (2 * abs(math.sin(Omega0 / 2)))
    K0 = -depth * np.linspace(0.1, 0.8, 8)
    never = {}
    for sign in (1, -1):
        m = _model(sign * EPS, Omega0, tau0, b1)
        res = m.iterate(m.L1(K0), K0, 20_000, record=(), exit_regions={"0u", "0"}, stop_on_exit=True)
        never[sign] = res.exit_step == -1
    if never[1].all() and not never[-1].any():
        return 1
    if never[-1].all() and not never[1].any():
        return -1
    return 0


@pytest.mark.parametrize("x", TURNS)
def test_the_sign_that_hovers_is_sign_of_sin_half_omega_times_b1_at_every_omega(x):
    # 4 maps x 2 signs x 8 orbits x 20,000 steps per Omega0 (~0.1 s). Exact verdicts: a start in the
    # band between the critical curve and K = 0 lies on an invariant curve that never impacts (the
    # hovering sign), and for the other sign the curves through it dip into J_R near L2 within a
    # few steps (measured: every start impacts within 1-5 steps).
    Omega0 = 2 * math.pi * x
    for tau0 in (1.0, -1.0):
        for b1 in (1.0, -0.7):
            rule = int(np.sign(math.sin(Omega0 / 2) * b1))
            assert _measured_hovering_sign(Omega0, tau0, b1) == rule, (x, tau0, b1)
            th = hv.theory(EPS * rule, Omega0, THETA_W, tau0, forcing=(b1,))
            assert th.hovers and th.hovering_sign == rule
            assert not hv.theory(-EPS * rule, Omega0, THETA_W, tau0, forcing=(b1,)).hovers
    # Not a rule mod 2 pi: Omega0 and Omega0 + 2 pi hover for opposite signs of eps.
    assert _measured_hovering_sign(Omega0 + 2 * math.pi, 1.0, 1.0) == -int(np.sign(math.sin(Omega0 / 2)))


def test_a_first_mode_within_rounding_of_zero_is_no_first_order_forcing():
    # b_1 = 3e-17 beside b_2 = 0.015: below the rounding bound of a 256-sample sine fit,
    # 2 (256 + 2) u sum |b_k| = 8.6e-16 (u = 2^-53), so it is taken as 0 and the higher mode decides.
    th = hv.theory(EPS, 9.8347, 2.4445, 3.0788, forcing=(3e-17, 0.015))
    assert th.forcing_tol == pytest.approx(2 * 258 * 2.0**-53 * (0.015 + 3e-17), rel=1e-15)
    assert th.forcing == (0.0, 0.015) and "no first-order forcing" in th.note and "b_1 = 3e-17" in th.note
    assert th.hovers and th.hovering_sign == 1 and th.area > 0  # through b_2 (as the flow: see tests/normal)
    # Every mode within the tolerance: f = 0, K' = K, nothing hovers, the sign is 0, and the note says why.
    none = hv.theory(EPS, 9.8347, 2.4445, 3.0788, forcing=(1e-17, -2e-17), forcing_tol=1e-16)
    assert (none.hovers, none.area, none.hovering_sign) == (False, 0.0, 0) and none.forcing == (0.0, 0.0)
    assert math.isnan(none.K_crit) and none.K_lowest == 0.0 and "no forcing" in none.note
    # A forcing given as 1e-17 alone is not noise relative to itself (the user's scale): kept.
    tiny = hv.theory(EPS, 1.0, 2.0, forcing=(1e-17,))
    assert tiny.forcing == (1e-17,) and tiny.hovering_sign == 1
    with pytest.raises(ValueError, match="forcing_tol must lie in"):
        hv.theory(EPS, 1.0, 2.0, forcing_tol=-1.0)


@pytest.mark.parametrize("eps", [0.1, -0.1])
def test_wall_and_no_wall_geometries_have_no_hovering_set(eps):
    # The step's theory would give |HOV| = 0.255 for one of these signs; without the step's corner
    # there is no J_0 (every K < 0 point impacts the wall, eq:fwall), so HOV is empty exactly.
    step = hv.theory(eps, hv.OMEGA_G, THETA_W)
    wall = hv.theory(eps, hv.OMEGA_G, THETA_W, geometry="wall")
    assert (wall.hovers, wall.area, wall.hovering_sign, wall.geometry) == (False, 0.0, 0, "wall")
    assert "geometry 'wall'" in wall.note and "does not apply" in wall.note and math.isnan(wall.K_crit)
    # k^{u0}, the lowest first-order curve at K >= 0: on L1 at 0 for the sign that hovers on the step,
    # -eps / sin(Omega0/2) > 0 otherwise (eq:keps2 through L2 at 0).
    s = math.sin(hv.OMEGA_G / 2)
    assert wall.K_lowest == pytest.approx(max(0.0, -eps / s), abs=1e-15)
    assert step.hovers == (eps > 0)
    free = hv.theory(eps, hv.OMEGA_G, THETA_W, geometry="none")
    assert (free.hovers, free.area, free.hovering_sign) == (False, 0.0, 0) and "no walls" in free.note
    with pytest.raises(ValueError, match="geometry must be one of"):
        hv.theory(eps, hv.OMEGA_G, THETA_W, geometry="corner")


def test_the_docs_state_the_sign_rule_for_every_omega():
    # The rule is sign(sin(Omega0/2) b_1), of period 4 pi: no page may say that Omega0 mod 2 pi sets
    # the sign, and the corrections page and the tutorial state the rule itself.
    pages = [ROOT / "README.md", *(ROOT / "docs").rglob("*.md"), *(ROOT / "examples").rglob("*.py")]
    pages += list((ROOT / "python" / "hovering").rglob("*.py"))
    wrong = re.compile(r"mod(ulo)? 2 ?pi`*\)? (sets|decides|gives|fixes) the sign")
    bad = [str(p.relative_to(ROOT)) for p in pages if wrong.search(p.read_text())]
    assert not bad, bad
    errata = (ROOT / "docs" / "guide" / "errata.md").read_text()
    assert "`sign(sin(Omega0 / 2) * b_1)`" in errata and "period in `Omega0` is 4 pi" in errata
    assert "sign(sin(Omega0 / 2) * b1)" in (ROOT / "examples" / "gallery" / "plot_your_own_system.py").read_text()
    # and the corrections page links nothing outside the repository (it used to cite shared/PAPER-NOTES.md)
    assert "PAPER-NOTES" not in errata and "shared/" not in errata
