"""FlowMap.theory(), truncated() and repr for what the paper's step theory does not cover: the wall
geometry (no step corner: nothing hovers), a measured forcing whose first mode is rounding noise
(a coupling even in q2: the higher modes act) or whose every mode is (no forcing)."""

from __future__ import annotations

import numpy as np
import pytest

import hovering as hv
from hovering import paper
from hovering.normal import TangentialCurve

EVEN_IN_Q2 = hv.Polynomial({(1, 2): 1.0})  # Vc = q1 q2^2: f has only even sine modes, b_1 = 0 exactly
NO_ODD_PART = hv.Polynomial({(0, 2): 1.0})  # Vc = q2^2: I_tan^eps(theta) stays even, f = 0 exactly


@pytest.mark.parametrize("eps", [-0.05, 0.05])
def test_the_wall_geometry_has_no_hovering_set_and_no_step_model(eps):
    fm = hv.FlowMap(paper.system(eps=eps, geometry="wall"), h=1.0)
    # Measured: every start below the tangential curve impacts the wall on its first return (there
    # is no corner to pass above), so J_0 is empty; exact, not a statistic.
    rng = np.random.default_rng(3)
    lo = fm.valid_band()[0]
    r = fm.returns(rng.uniform(-np.pi, np.pi, 400), rng.uniform(0.95 * lo, -1e-4, 400))
    assert np.all(r.status == hv.FlowStatus.OK) and np.all(r.region == int(hv.Region.RIGHT))
    th = fm.theory()
    # The step's theory said hovers=True, |HOV| = 0.0745 for eps = -0.05 here: not for the wall.
    assert (th.hovers, th.area, th.hovering_sign, th.geometry) == (False, 0.0, 0, "wall")
    assert "geometry 'wall'" in th.note and "HOV" in th.note
    assert fm.hovers() is False
    with pytest.raises(ValueError, match="geometry 'wall'.*step's corner"):
        fm.truncated()
    with pytest.raises(ValueError, match="geometry 'wall'"):
        fm.truncated(forcing="first_mode")
    assert "geometry 'wall': no step corner" in repr(fm)
    # The same system with the step hovers for eps < 0 (Omega0 = 9.83, b_1 = 0.564 > 0).
    assert fm.with_eps(eps).sys.geometry == "wall"
    step = hv.FlowMap(paper.system(eps=eps), h=1.0)
    assert step.theory().hovers == (eps < 0) and step.theory().hovering_sign == -1


def test_the_tolerance_bounds_the_measured_forcing_error():
    # tol = 4 delta / |eps| + 2 (n + 2) u sum |b_k| is a bound on |b_k - b_k(true)|. Compared with
    # an independent measurement (a curve of twice the wall points traced at rtol 1e-15): the
    # difference lies below it (measured up to 3.5e-14 against tol 4.9e-13), and tol is far below every
    # coefficient that matters here (b_1 = 0.564; b_8 = 3e-7 is kept).
    fm = hv.FlowMap(paper.system(eps=-0.05), h=1.0)
    b, tol = fm.forcing_coefficients(), fm.forcing_tolerance()
    ref = TangentialCurve(fm.section, n=2 * fm.curve.s.size, rtol=1e-15).forcing_coefficients()
    assert np.abs(b - ref).max() < tol < 1e-11
    th = fm.theory()
    assert th.forcing == tuple(b) and th.forcing_tol == tol  # nothing of this forcing is noise
    assert repr(fm).endswith("# effective eps = eps b1 = -0.0282 (b1 = 0.5639), band K in [-0.2966, 0.2638]")


def test_a_coupling_even_in_q2_has_no_first_order_forcing_but_hovers_through_higher_modes():
    fm = hv.FlowMap(paper.system(eps=0.05, coupling=EVEN_IN_Q2), h=1.0)
    b, tol = fm.forcing_coefficients(), fm.forcing_tolerance()
    # b_1 is rounding noise (measured -6.1e-15) within the bound (4.0e-13); b_2 = 0.0153 is not.
    assert abs(b[0]) < tol < 1e-11 and abs(b[1]) > 0.01
    text = repr(fm)
    # The old repr said "effective eps = eps b1 = -3.058e-16": as if nothing forced the model.
    assert "effective eps" not in text and "the first mode vanishes" in text and "higher modes act" in text
    assert "eps b2 = 0.000763" in text
    th = fm.theory()
    assert th.forcing[0] == 0.0 and th.forcing[1] == b[1] and "no first-order forcing" in th.note
    assert th.hovers and th.hovering_sign == 1 and th.area == pytest.approx(0.002447, rel=1e-3)
    # The flow agrees: it hovers for eps > 0 (1000 stratified samples, 400 returns; the estimate
    # 0.0022 +- 0.0004 against the theory's 0.00245, within 2 error bars) and not for eps < 0.
    ha = hv.hovering_area(fm, n_steps=400, n_samples=1000)
    assert ha.area > 0 and abs(ha.area - th.area) < 2 * ha.error
    neg = fm.with_eps(-0.05)
    assert not neg.theory().hovers and hv.hovering_area(neg, n_steps=400, n_samples=1000).area == 0.0
    # Its model carries the same forcing, b_1 = 0: the first-mode model is F_0.
    assert fm.truncated().theory().forcing[0] == 0.0 and fm.truncated(forcing="first_mode").eps == 0.0


def test_a_forcing_that_is_noise_in_every_mode_predicts_nothing():
    fm = hv.FlowMap(paper.system(eps=0.05, coupling=NO_ODD_PART), h=1.0)
    b, tol = fm.forcing_coefficients(), fm.forcing_tolerance()
    assert np.abs(b).max() < tol  # measured up to 4.2e-14 against 3.9e-13
    th = fm.theory()
    # The old theory said hovers=True with |HOV| = 2.5e-16 and sign 0.
    assert (th.hovers, th.area, th.hovering_sign) == (False, 0.0, 0) and not any(th.forcing)
    assert "no forcing" in th.note and "no forcing: every b_k is 0 within its error" in repr(fm)
