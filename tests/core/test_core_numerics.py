"""The sweep numerics have one owner, the C++ core, and Python calls it: the hovering area's samples
(numpy's default_rng stream, drawn in C++), per-sample outcomes, estimate and default box; the
measured forcing's one fit; the integrator defaults and the stepper list. Each is checked here
against an independent computation with NumPy (the formulas hovering.hovering_area used before
they moved to the core)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import hovering as hv
from conftest import PAPER  # hovering.paper.FIGURE
from hovering import _core, paper
from hovering.analysis.hovering import _outcomes, _stratified, default_depth


def numpy_samples(samples, K_low, seed):
    """The stratified samples as hovering.hovering_area drew them with NumPy."""
    rng = np.random.default_rng(seed)
    H = -K_low
    n_phi = int(min(max(1, round(math.sqrt(samples * 2 * math.pi / H))), samples))
    n_K = max(1, int(math.ceil(samples / n_phi)))
    i, j = np.meshgrid(np.arange(n_phi), np.arange(n_K), indexing="ij")
    phi = -math.pi + (i.ravel() + rng.random(i.size)) * (2 * math.pi / n_phi)
    K = K_low + (j.ravel() + rng.random(j.size)) * (H / n_K)
    return phi, np.minimum(K, -1e-300)


@pytest.mark.parametrize(
    "samples, K_low, seed", [(1, -0.1, 0), (1500, -0.37, 3), (20_000, -3.0, 2**40 + 1), (777, -1e-3, 2**63 - 1)]
)
def test_samples_are_numpys_stream_and_pieces_are_slices(samples, K_low, seed):
    phi, K = _stratified(samples, K_low, seed)
    rphi, rK = numpy_samples(samples, K_low, seed)
    assert np.array_equal(phi, rphi) and np.array_equal(K, rK)  # the same doubles
    n = phi.size
    for lo, hi in ((0, n), (0, 1), (n // 3, n // 2), (n - 1, n), (n, n)):
        p, k = _stratified(samples, K_low, seed, lo, hi)
        assert np.array_equal(p, phi[lo:hi]) and np.array_equal(k, K[lo:hi])
    with pytest.raises(ValueError, match=r"sample range \[2, 1\) must lie in \[0, "):
        _stratified(samples, K_low, seed, 2, 1)


def maps():
    m = hv.TruncatedMap(eps=0.15, **PAPER)
    fam = hv.TruncatedFamily.from_map(
        m, np.concatenate([-(np.linspace(1, 0, 30) ** 2), [0.5, 1.0]]), forcing=(1.0, 0.3, -0.1)
    )
    return {"truncated": (m, 400), "family": (fam, 400), "flow": (paper.flow_map(-0.1), 60)}


@pytest.mark.parametrize("name", ["truncated", "family", "flow"])
def test_outcomes_and_estimate_are_the_definitions(name):
    m, n_steps = maps()[name]
    K_low = -0.1
    phi, K = _stratified(300, K_low, 1)
    s0, s1, steps, visited = _outcomes(m, phi, K, n_steps, 0)
    # Independently: F_0 then F_eps through the public iterate, early exit from {J_0u, J_0}.
    r0 = m.with_eps(0.0).iterate(phi, K, n_steps, record=(), exit_regions=("0u", "0"), stop_on_exit=True)
    r = m.iterate(phi, K, n_steps, record=("visited",), exit_regions=("0u", "0"), stop_on_exit=True)
    assert np.array_equal(s0, r0.status) and np.array_equal(s1, r.status)
    assert np.array_equal(steps, r.steps_done) and np.array_equal(visited, r.visited)
    # The estimate, as NumPy computed it.
    e = _core.analysis.hovering_estimate(s0, s1, steps, visited, K, n_steps, K_low, True)
    impacts0 = np.isin(s0, [int(hv.Status.EXITED), int(hv.Status.CORNER), int(hv.Status.GRAZING)])
    stayed = s1 == hv.Status.OK
    box = 2 * math.pi * -K_low
    areas = [
        box * np.count_nonzero(impacts0 & (stayed | (steps >= N))) / K.size
        for N in (n_steps // 4, n_steps // 2, n_steps)
    ]
    hov = impacts0 & stayed
    p = np.count_nonzero(hov) / K.size
    sampling = box * math.sqrt(max(p * (1 - p), 1.0 / K.size) / K.size)
    assert (e["area_N4"], e["area_N2"], e["area"]) == tuple(areas)
    assert e["sampling_error"] == sampling and e["error"] == 2 * sampling + (areas[1] - areas[2])
    both = (1 << int(hv.Region.BESIDE)) | (1 << int(hv.Region.ABOVE))
    assert np.array_equal(e["hovering"], hov) and np.array_equal(e["both_sides"], hov & ((visited & both) == both))
    assert e["floor_touched"] == bool(np.any(hov & (K < 0.9 * K_low)))
    assert e["unresolved"] == np.count_nonzero(
        ~np.isin(s1, [int(hv.Status.OK), int(hv.Status.EXITED), int(hv.Status.ESCAPED)])
    )
    if name != "flow":
        assert 0 < e["area"] < box  # something hovers, something does not: the counts are tested


def test_default_box_is_twice_the_deepest_first_order_curve():
    for eps, Om in ((0.1, hv.OMEGA_G), (-0.3, 2.0), (0.05, 5.5)):
        m = hv.TruncatedMap(eps=eps, Omega0=Om, theta_w=2.0)
        psi = np.linspace(-np.pi, np.pi, 4001)
        G = (1 - np.cos(psi)) / (2 * np.sin(0.5 * Om))
        ref = 2 * abs(eps) * np.max(np.abs(G))
        # NumPy's cos may differ from the C library's by an ulp on some machines: 2 ulps of slack.
        assert default_depth(m) == pytest.approx(ref, rel=4.5e-16, abs=0)
        assert default_depth(m) == pytest.approx(2 * abs(eps) / abs(math.sin(0.5 * Om)), rel=1e-12)
        assert hv.hovering_area(m, n_steps=4, n_samples=1).box[2] == max(
            -default_depth(m), m.valid_band()[0] * (1 - 1e-9)
        )
    th = hv.theory(0.1, 2.0, 2.0, forcing=(1.0, 0.4, -0.2))
    psi = np.linspace(-3, 3, 7)
    G = sum(b * (1 - np.cos((k + 1) * psi)) / (2 * math.sin(0.5 * (k + 1) * 2.0)) for k, b in enumerate(th.forcing))
    assert np.allclose(th.G(psi), G, rtol=4.5e-16, atol=1e-16) and isinstance(th.G(0.5), float)


def test_the_measured_forcing_has_one_fit():
    fm = paper.flow_map(0.05)
    b = fm.forcing_coefficients()
    assert b.size == _core.normal.FORCING_MODES == 8
    # The least-squares fit of the same samples (what NumPy computed before): the modes are
    # orthogonal on the midpoint angles, so the fit is the discrete sine transform up to rounding.
    ph = _core.normal.forcing_angles(_core.normal.FORCING_SAMPLES)
    f = fm.curve.forcing(ph)
    A = np.stack([np.sin((k + 1) * ph) for k in range(8)], 1)
    lstsq = np.linalg.lstsq(A, f, rcond=None)[0]
    assert np.max(np.abs(b - lstsq)) < 1e-14 * np.max(np.abs(b))  # measured: 1e-16 here, <= 8e-16 at eps -0.1, 0.2
    assert np.array_equal(b, fm.curve.forcing_coefficients()) and np.array_equal(fm.truncated().forcing, b)
    # f = b_1 sin + b_2 sin 2 phi exactly: recovered to rounding.
    g = 0.7 * np.sin(ph) - 0.2 * np.sin(2 * ph)
    assert np.allclose(_core.normal.sine_coefficients(g, 3), [0.7, -0.2, 0.0], rtol=0, atol=1e-15)
    # The bisection-measured f through the same fit: an independent measurement of the same modes.
    bb = hv.forcing_coefficients(fm.section, n_modes=3, n_phi=16)
    assert np.allclose(bb, b[:3], rtol=0, atol=1e-8)
    with pytest.raises(ValueError, match=r"n_phi \(> 2 n_modes, so the fit is determined\) must be an integer in \[7"):
        hv.forcing_coefficients(fm.section, 3, 6)


def test_integrator_defaults_and_steppers_are_the_cores():
    d = _core.flow.FlowOptions()
    assert hv.flow.STEPPERS == tuple(_core.flow.STEPPERS) and hv.flow.STEPPERS[0] == d.stepper
    o = hv.flow.flow_options()
    assert (o.stepper, o.rtol, o.atol, o.max_steps) == (d.stepper, d.rtol, d.atol, d.max_steps)
    # One atol policy, the core's: where none is given atol is rtol's (FlowOptions::default_atol),
    # for the core's own defaults, for flow_options (Section.return_map), FlowMap and the scenes.
    assert d.atol == d.rtol == _core.flow.default_atol(d.rtol)
    assert hv.flow.flow_options(rtol=1e-8).rtol == 1e-8 and hv.flow.flow_options(rtol=1e-8).atol == 1e-8
    assert hv.flow.flow_options(rtol=1e-8, atol=1e-13).atol == 1e-13
    fm = paper.flow_map(0.05, coordinates="section")
    # The default "auto" as the map resolved it on its system (Harmonic x Tan: taylor).
    assert fm.integrator_options == dict(rtol=d.rtol, atol=d.rtol, stepper=d.resolved_for(fm.sys.core).stepper)
    assert d.stepper == "auto" and fm.integrator_options["stepper"] == "taylor"
    spec = hv.scenes.load_scene(Path(hv.scenes.__file__).parent / "data" / "demo.toml", check_output=False)
    assert (spec.integrator.stepper, spec.integrator.rtol, spec.integrator.atol) == (d.stepper, 1e-10, 1e-10)
    # The stepper is parsed once, by the core: its message names the value and every stepper.
    with pytest.raises(
        ValueError,
        match=r"stepper must be one of auto .*, rk8pd, rkck, .*GSL's bsimp and msbdf are not offered.*got 'euler'",
    ):
        hv.flow.flow_options(stepper="euler")
