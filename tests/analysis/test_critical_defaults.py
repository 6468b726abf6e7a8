"""critical_curve's defaults can give an answer at both signs of eps and at large |eps|."""

from __future__ import annotations

import pytest

import hovering as hv


@pytest.mark.parametrize("eps", [0.3, -0.3])
def test_default_range_is_inside_the_band_at_large_eps(eps):
    # The default range ended on the band's top edge (or started above its own end) and the
    # search refused it: "K_range must be increasing inside the band" at |eps| = 0.3.
    m = hv.paper.flow_map(eps=eps)
    lo, hi = m.valid_band()
    c = hv.critical_curve(m, n_steps=2000, n_grid=16)
    assert lo < c.K0 < hi


def test_the_non_hovering_sign_finds_k_u0_not_the_tori_under_the_zone():
    # At eps = +0.2 the README flow does not hover (theory); the lowest curve avoiding impacts is
    # k^{u0}, crossing L2 at K >= 0. The old default range started at -2 |eps| / |sin(Omega0/2)|,
    # below the zone's floor, and returned the band's bottom edge (K0 = -0.182) as the "curve".
    m = hv.paper.flow_map(eps=0.2)
    assert not m.theory().hovers
    c = hv.critical_curve(m, n_steps=2000, n_grid=16)
    assert not c.hovers
    # measured 0.0023; the band's bottom is -0.182: any K0 above -0.01 is k^{u0}'s crossing
    assert c.K0 > -0.01


def test_a_reversed_range_is_refused_by_name():
    # a given range is checked too (the default is built inside the band, above)
    m = hv.paper.truncated_map(eps=0.05)
    with pytest.raises(ValueError, match="K_range"):
        hv.critical_curve(m, K_range=(0.5, 0.4))
