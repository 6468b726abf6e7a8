"""StepSystem validation and onset parameters: definitions vs quadrature vs the appendix (issue 4, part)."""

from __future__ import annotations

import math

import pytest

import hovering
from hovering import Bilinear, Harmonic, StepSystem, Tan, onset_parameters, paper

FIELDS = ("Omega0", "tau0", "tau1", "lam", "theta_w", "I_tan")


def system(V1, V2, qw1=-1.0, qw2=-0.5):
    return StepSystem(V1=V1, V2=V2, coupling=Bilinear(), eps=0.05, qw1=qw1, qw2=qw2, geometry="step")


@pytest.mark.parametrize(
    "V1,V2,qw1,qw2,h",
    [
        (paper.V1, paper.V2, paper.QW1, paper.QW2, paper.H),  # the example (hovering.paper's system)
        (Tan(1.0, 0.6), Tan(1.4, 0.7), -0.8, -0.4, 1.2),
        (Tan(1.2, 0.9), Harmonic(1.0), -0.7, -0.6, 1.5),
        (Harmonic(1.0), Harmonic(1.3), -1.0, -0.5, 2.0),
    ],
)
def test_three_ways_to_the_onset_parameters_agree(V1, V2, qw1, qw2, h):
    # Definitions with closed-form action-angle variables, the same definitions by pure GSL
    # quadrature, and the (corrected) appendix formulas: three computations that share only the
    # definitions. Derivatives carry ~1e-9 (Richardson differences of ~1e-13 quantities): 1e-7.
    sys = system(V1, V2, qw1, qw2)
    d = onset_parameters(sys, h)
    q = onset_parameters(sys, h, method="quadrature")
    c = onset_parameters(sys, h, method="closed_form")
    for f in FIELDS:
        a, b, e = getattr(d, f), getattr(q, f), getattr(c, f)
        assert abs(a - b) <= 1e-7 * max(1, abs(a)), (f, a, b)
        assert abs(a - e) <= 1e-7 * max(1, abs(a)), (f, a, e)
    # qw2 < 0: the corner angle is past a quarter turn and tau1 > 0 (sign tau1 = -sign qw2).
    assert math.pi / 2 < d.theta_w < math.pi and d.tau1 > 0
    # H2(I_tan) = h - V1(qw1) (eq:Itan).
    assert abs(sys.V2.energy(d.I_tan) - (h - sys.V1.V(qw1))) < 1e-12


def test_harmonic_pair_has_no_twist():
    # Appendix limit alpha1, alpha2 -> 0: tau0 = 0 and Omega0 = 2 pi omega2 / omega1 for every h.
    sys = system(Harmonic(1.0), Harmonic(1.3))
    for h in (1.0, 2.0, 3.0):
        p = onset_parameters(sys, h)
        assert abs(p.tau0) < 1e-7 and abs(p.Omega0 - 2 * math.pi * 1.3) < 1e-12


def test_printed_tau0_disagrees_with_the_definition():
    # The appendix prints tau0 = 2 pi [alpha2^2 W1^3 + alpha1^2 W2^2] / W1^4; differentiating
    # Omega0(I) = 2 pi omega2(I) / omega1(h - H2(I)) gives W1^3 in the last term. Numbers decide.
    V1, V2, h = Tan(1.0, 0.6), Tan(1.4, 0.7), 1.2
    sys = system(V1, V2, -0.8, -0.4)
    d = onset_parameters(sys, h, method="quadrature")
    h1w = V1.V(-0.8)
    W1 = math.sqrt(1.0 + 2 * 0.36 * h1w)
    W2 = math.sqrt(1.4**2 + 2 * 0.49 * (h - h1w))
    printed = 2 * math.pi * (0.49 * W1**3 + 0.36 * W2**2) / W1**4
    corrected = 2 * math.pi * (0.49 / W1 + 0.36 * W2**2 / W1**3)
    assert abs(d.tau0 - corrected) < 1e-7 and abs(d.tau0 - printed) > 1e-2


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="h must exceed the step energy"):
        onset_parameters(system(paper.V1, paper.V2), h=0.6)
    with pytest.raises(ValueError, match="geometry must be one of"):
        StepSystem(V1=paper.V1, V2=paper.V2, geometry="steps")
    with pytest.raises(ValueError, match=r"qw2 = -3.0 lies outside the well"):
        StepSystem(V1=paper.V1, V2=paper.V2, qw2=-3.0)
    with pytest.raises(ValueError, match="qw1 must be finite and < 0"):
        StepSystem(V1=paper.V1, V2=paper.V2, qw1=0.5)
    with pytest.raises(ValueError, match="eps != 0 needs a coupling"):
        StepSystem(V1=paper.V1, V2=paper.V2, eps=0.1)
    with pytest.raises(ValueError, match=r"omega must lie in \[1e-100, 1e100\], got 0"):
        Harmonic(0.0)
    with pytest.raises(ValueError, match="method must be"):
        onset_parameters(system(paper.V1, paper.V2), 1.0, method="guess")
    assert system(paper.V1, paper.V2).step_energy == pytest.approx(0.5 + hovering.Tan(1.4, 0.7).V(-0.5))
