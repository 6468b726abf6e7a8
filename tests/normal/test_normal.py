"""Tangential curve, f(phi) and normal coordinates (eq:kphidef, eq:defoff) of the flow."""

from __future__ import annotations

import numpy as np
import pytest

from hovering import (
    forcing_function,
    from_normal,
    paper,
    tangential_curve,
    to_normal,
)


def sec(eps, geometry="step"):
    return paper.section(eps, geometry)


def test_uncoupled_tangential_curve_is_the_tangent_circle():
    # eps = 0: I_tan^0(theta) = H2^{-1}(h - V1(qw1)) (eq:Itan) for every theta; the bisection
    # stops where the wall distance's minimum is within grazing_tol = 1e-12 of zero: 1e-11.
    s = sec(0.0)
    I0 = s.sys.V2.action(1.0 - s.sys.V1.V(-1.0))
    assert np.abs(tangential_curve(s, np.linspace(-3, 3, 9)) - I0).max() < 1e-11


def test_image_of_the_tangential_curve_is_its_reflection():
    # Time reversal makes the image of sigma_tan the reflection of sigma_tan: bar I_tan(theta) =
    # I_tan(-theta) (sec:setup). Checked by mapping the computed curve with the smooth flow (the
    # tangential orbits only touch q1 = qw1): to 1e-9 (two bisections at ~1e-15 and a return at
    # rtol 1e-12; observed 5e-14).
    s = sec(0.05)
    th = np.linspace(-3, 3, 13)
    It = tangential_curve(s, th)
    assert np.ptp(It) > 1e-2  # really eps-deformed, not the constant circle
    out = sec(0.05, geometry="none").return_map(th, It, rtol=1e-12, atol=1e-14)
    assert np.abs(out.I - tangential_curve(s, -out.theta)).max() < 1e-9


def test_forcing_is_odd_and_normal_coordinates_roundtrip():
    s = sec(0.05)
    phi = np.array([0.4, 1.3, 2.5])
    f = forcing_function(s, np.concatenate([phi, -phi]))
    assert np.abs(f[:3] + f[3:]).max() < 1e-12 and np.abs(f).max() > 0.1
    p, K = to_normal(s, phi, np.full(3, 0.3))
    th, I = from_normal(s, p, K)
    assert np.array_equal(th, phi) and np.abs(I - 0.3).max() < 1e-15
    with pytest.raises(ValueError, match="defined for eps != 0"):
        forcing_function(sec(0.0), phi)
