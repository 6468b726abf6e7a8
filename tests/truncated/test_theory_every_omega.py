"""The theory of sec:truncinvcurves for every Omega0 and any odd forcing, against brute force.

The paper states it for Omega0 in (0, 2 pi). Written with sin(Omega0/2) it holds everywhere: the
sign of eps that hovers is the sign of sin(Omega0/2) (F_eps(.; Omega0) = F_-eps(. + pi; Omega0 +
2 pi) - (pi, 0)). Checked by measuring |HOV| in the critical band on both sides of 2 pi.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import hovering as hv
from hovering import paper

OMEGA_IN = hv.OMEGA_G  # 3.883: sin(Omega0/2) > 0
OMEGA_OUT = hv.OMEGA_G + 2 * math.pi  # 10.17: sin(Omega0/2) < 0


@pytest.mark.parametrize("Omega0", [OMEGA_IN, OMEGA_OUT])
@pytest.mark.parametrize("eps", [0.1, -0.1])
def test_hovering_sign_and_area_for_every_omega(Omega0, eps):
    m = hv.TruncatedMap(eps=eps, Omega0=Omega0, theta_w=3 * math.pi / 4)
    th = m.theory()
    hovers = eps * math.sin(Omega0 / 2) > 0
    assert th.hovers == hovers and m.hovers() == hovers
    assert th.hovering_sign == (1 if math.sin(Omega0 / 2) > 0 else -1)
    hv_area = hv.hovering_area(m, n_steps=4000, n_samples=20_000)
    assert hv_area.theory == th.area
    if hovers:
        # eq:hovsetsize: 0.2546 for eps = 0.1 at the paper's parameters; measured 0.2519 +- 0.0033
        # (1e5 samples); here 2e4 samples: within the error bar plus the O(eps^2) ~ 0.3 eps^2.
        assert th.area == pytest.approx(
            abs(eps)
            * (math.sin(3 * math.pi / 4) - 3 * math.pi / 4 * math.cos(3 * math.pi / 4))
            / abs(math.sin(Omega0 / 2)),
            rel=1e-12,
        )
        assert abs(hv_area.area - th.area) < hv_area.error + 0.3 * eps**2
        assert th.K_crit < 0 and th.K_crit == pytest.approx(m.K_crit(), rel=1e-12)
        assert th.rho_crit == pytest.approx(m.rho_crit(), rel=1e-12)
    else:
        assert th.area == 0.0 and math.isnan(th.K_crit) and "no hovering set" in th.note
        assert hv_area.area == 0.0  # thm:hovering's destruction, measured in the critical band
        assert th.K_lowest > 0  # k^{u0}: its height on L1 is -eps / sin(Omega0/2) > 0


def test_symmetry_behind_it():
    # F_eps(phi, K; Omega0) = F_-eps(phi + pi, K; Omega0 + 2 pi) - (pi, 0) on the whole band.
    a = hv.TruncatedMap(eps=0.2, Omega0=OMEGA_IN, theta_w=2.0)
    b = hv.TruncatedMap(eps=-0.2, Omega0=OMEGA_OUT, theta_w=2.0)
    rng = np.random.default_rng(0)
    phi, K = rng.uniform(-math.pi, math.pi, 500), rng.uniform(-0.5, 0.5, 500)
    pa, Ka = a.step(phi, K)
    pb, Kb = b.step(hv.wrap(phi + math.pi), K)
    assert np.abs(hv.wrap(pb - math.pi - pa)).max() < 1e-12 and np.abs(Kb - Ka).max() < 1e-12


def test_critical_curve_on_the_sign_that_does_not_hover_says_so():
    m = paper.truncated_map(-0.3)
    cc = hv.critical_curve(m, n_steps=4000)
    # The lowest curve avoiding the impacts is k^{u0}: minimum ~0 on L2 (thm:minmaxinvriantcurves).
    assert not cc.hovers and cc.line == "L2" and "no hovering set" in cc.note
    assert -0.02 < cc.K_min < 0.02 and cc.K0 > -0.02
    with pytest.raises(RuntimeError, match="impacting case"):
        hv.critical_curve(m, n_steps=4000, line="L1", K_range=(-0.3, -0.05))


def test_multimode_theory_reduces_to_the_closed_forms():
    # A forcing b_1 sin(phi) + tiny b_2: the numerical leading-order curve converges to the closed
    # forms (n_grid^-2: 1e-5 relative at 2001 points, the b_2 term is O(b_2)).
    base = hv.theory(0.1, hv.OMEGA_G, 2.2, forcing=(0.8,))
    multi = hv.theory(0.1, hv.OMEGA_G, 2.2, forcing=(0.8, 1e-9), n_grid=2001)
    assert multi.area == pytest.approx(base.area, rel=1e-5)
    assert multi.K_crit == pytest.approx(base.K_crit, rel=1e-6)
    assert multi.rho_crit == pytest.approx(base.rho_crit, rel=1e-6)
    assert base.area == pytest.approx(
        0.08 * (math.sin(2.2) - 2.2 * math.cos(2.2)) / math.sin(hv.OMEGA_G / 2), rel=1e-14
    )
    # and its hovering set against brute force on a TruncatedFamily with that forcing
    fam = hv.TruncatedFamily.from_map(
        hv.TruncatedMap(eps=0.1, Omega0=hv.OMEGA_G, theta_w=2.2),
        np.concatenate([-(np.linspace(1.0, 0.0, 81) ** 2), np.linspace(0.02, 1.0, 30)]),
        forcing=(0.8, 0.15),
    )
    th = fam.theory()
    assert th.hovers and th.forcing == (0.8, 0.15)
    meas = hv.hovering_area(fam, n_steps=4000, n_samples=20_000)
    assert abs(meas.area - th.area) < meas.error + 0.3 * 0.1**2


def test_resonant_and_degenerate_cases_are_named():
    th = hv.theory(0.1, 2 * math.pi, 2.0)
    assert math.isnan(th.area) and "resonant" in th.note
    assert math.isnan(hv.hovering_area_theory(0.1, 2.0, 2 * math.pi))
    assert hv.hovering_area_theory(-0.1, 2.0, hv.OMEGA_G) == 0.0  # the old formula gave a negative area
    assert "no twist" in hv.theory(0.1, 1.0, 2.0, tau0=0.0).note
    with pytest.raises(ValueError, match="eps must be finite, got nan"):
        hv.theory(float("nan"), 1.0, 2.0)
