"""Every bad input the reliability audit found (issue 11) is a ValueError naming the parameter, its
value and what is allowed, raised before any long computation; helpers that used to return
silent garbage now refuse or answer NaN where the quantity does not exist.

Each case is one line: the call and a regular expression the message must match. The regexes name
the parameter *and* the range, so a message that loses either fails here."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest

import hovering as hv
from hovering import paper
from hovering.parallel.checkpoint import Checkpoint

M = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
FAM = hv.TruncatedFamily.from_map(M, np.concatenate([-(np.linspace(1.0, 0.0, 41) ** 2), np.linspace(0.02, 1.0, 10)]))
SYS = paper.system(0.05)
SEC = hv.Section(SYS, 1.0)
NAN = float("nan")

BAD = {
    # hangs and silent skips
    "critical tol=0": (lambda: hv.critical_curve(M, tol=0), r"tol must be finite and >= 1e-14 .* got 0"),
    "critical tol=1e-18": (lambda: hv.critical_curve(M, tol=1e-18), r"tol must be finite and >= 1e-14"),
    "critical tol=-1": (lambda: hv.critical_curve(M, tol=-1), r"tol must be finite and >= 1e-14 .* got -1"),
    "critical tol=nan": (lambda: hv.critical_curve(M, tol=NAN), r"tol must be finite .* got nan"),
    # unclear errors
    "critical n_grid=0": (
        lambda: hv.critical_curve(M, n_grid=0),
        r"n_grid must be an integer in \[2, 1000000\], got 0",
    ),
    "critical n_grid=2**63": (
        lambda: hv.critical_curve(M, n_grid=2**63),
        r"n_grid must be an integer in \[2, 1000000\]",
    ),
    "critical n_steps=0": (
        lambda: hv.critical_curve(M, n_steps=0),
        r"n_steps must be an integer in \[16, \d+\], got 0",
    ),
    "critical digits=nan": (lambda: hv.critical_curve(M, digits=NAN), r"digits must be a number in \(0, 16\], got nan"),
    "critical K_range 3": (
        lambda: hv.critical_curve(M, K_range=(-0.3, -0.2, 0.1)),
        r"K_range must be a pair \(K_lo, K_hi\)",
    ),
    "area n_samples=nan": (
        lambda: hv.hovering_area(M, n_samples=NAN),
        r"n_samples must be an integer in \[1, \d+\], got nan",
    ),
    "area n_samples=inf": (
        lambda: hv.hovering_area(M, n_samples=math.inf),
        r"n_samples must be an integer in \[1, \d+\], got inf",
    ),
    "area n_samples=2.5": (
        lambda: hv.hovering_area(M, n_samples=2.5),
        r"n_samples must be an integer in \[1, \d+\], got 2.5",
    ),
    "area rng=-1": (lambda: hv.hovering_area(M, rng=-1), r"rng must be an integer seed in \[0, \d+\].*got -1"),
    "area n_steps='100'": (
        lambda: hv.hovering_area(M, n_steps="100"),
        r"n_steps must be an integer in \[4, \d+\], got '100'",
    ),
    "return_map stepper=3": (
        lambda: SEC.return_map([0.1], [0.3], stepper=3),
        r"stepper must be one of auto .*rk8pd, .*got '3'",
    ),
    "return_map max_steps=2**70": (
        lambda: SEC.return_map([0.1], [0.3], max_steps=2**70),
        r"max_steps must be an integer in \[1, 4611686018427387904\], got 1180591620717411303424",
    ),
    "return_map max_steps=1.5": (
        lambda: SEC.return_map([0.1], [0.3], max_steps=1.5),
        r"max_steps must be an integer in \[1, ",
    ),
    "return_map n_threads=2**40": (
        lambda: SEC.return_map([0.1], [0.3], n_threads=2**40),
        r"n_threads must be an integer in \[0, 4096\] \(0 = all cores\), got 1099511627776",
    ),
    "return_map n_threads=1.7": (
        lambda: SEC.return_map([0.1], [0.3], n_threads=1.7),
        r"n_threads must be an integer in \[0, 4096\]",
    ),
    "return_map n_threads='2'": (
        lambda: SEC.return_map([0.1], [0.3], n_threads="2"),
        r"n_threads must be an integer in \[0, 4096\]",
    ),
    "iterate n_threads=1.7": (
        lambda: M.iterate([0.1], [0.1], 3, n_threads=1.7),
        r"n_threads must be an integer in \[0, 4096\]",
    ),
    "iterate n_threads='2'": (
        lambda: M.iterate([0.1], [0.1], 3, n_threads="2"),
        r"n_threads must be an integer in \[0, 4096\]",
    ),
    "tangential bracket=1": (
        lambda: hv.tangential_curve(SEC, [0.1], bracket=1.0),
        r"bracket must lie in \(0, 1\), got 1.0",
    ),
    "tangential bisections=-1": (
        lambda: hv.tangential_curve(SEC, [0.1], bisections=-1),
        r"bisections must be an integer in \[1, 200\], got -1",
    ),
    "StepSystem eps='a'": (
        lambda: hv.StepSystem(V1=hv.Harmonic(1.0), V2=hv.Tan(1.4, 0.7), eps="a"),
        r"eps must be a real number, got 'a'",
    ),
    "Section h=None": (lambda: hv.Section(SYS, None), r"h must be a real number, got None"),
    "Polynomial {1: 1}": (lambda: hv.Polynomial({1: 1.0}), r"each key must be a pair of exponents \(i, j\)"),
    "family reversed grid": (
        lambda: hv.TruncatedFamily(0.1, [1.0, 0.5, 0.0, -0.5, -1.0], [2.0] * 5, [1.0] * 5, [0.0] * 5),
        r"K (grid )?must|strictly increasing|extend above",
    ),
    "onset_parameters('x', 1)": (lambda: hv.onset_parameters("x", 1), r"sys must be a hovering.StepSystem, got 'x'"),
    "coordinates(nan)": (lambda: SEC.coordinates(NAN), r"z must be states \(q1, p1, q2, p2\) of shape \(n, 4\)"),
    # silent garbage
    "reversal(nan)": (lambda: M.reversal(NAN, 0.1), r"phi must be finite, got nan"),
    "reversal(1e300)": (lambda: M.reversal(1e300, 0.1), r"phi must be an angle in \[-1e6, 1e6\] .*got 1e\+300"),
    "L1(nan)": (lambda: M.L1(NAN), r"K must be finite, got nan"),
    "wrap(1e300)": (lambda: hv.wrap(1e300), r"angles to wrap must satisfy \|x\| <= 1e6.*got 1e\+300"),
    "wrap(inf)": (lambda: hv.wrap(math.inf), r"angles to wrap must satisfy \|x\| <= 1e6"),
    "K_crit theta_w=4": (lambda: hv.K_crit(0.1, 4.0, 1.0), r"theta_w must lie in \(0, pi\), got 4.0"),
    "to_normal I=nan": (lambda: hv.to_normal(SEC, [0.1], [NAN]), r"I\[0\] must be finite, got nan"),
    "from_normal K=-100": (
        lambda: hv.from_normal(SEC, [0.1], [-100.0]),
        r"K = -100.0 gives the action I = -99.7\d* <= 0",
    ),
    "Harmonic angle off the level": (
        lambda: hv.Harmonic(1.0).angle_of_point(5.0, 0.0, 1.0),
        r"\(q, p\) = \(5, 0\) has energy p\^2/2 \+ V\(q\) = 12.5, not on the level h = 1",
    ),
    "Tan angle off the level": (lambda: hv.Tan(1.4, 0.7).angle_of_point(0.1, 3.0, 1.0), r"not on the level h = 1"),
    "Numerical angle p=nan": (
        lambda: hv.Numerical(hv.Harmonic(1.0)).angle_of_point(0.5, NAN, 1.0),
        r"q and p must be finite, got q = 0.5, p = nan",
    ),
    "Tan(1e-300, 1e300)": (lambda: hv.Tan(1e-300, 1e300), r"omega must lie in \[1e-100, 1e100\], got 1e-300"),
    "Harmonic(1e200)": (lambda: hv.Harmonic(1e200), r"omega must lie in \[1e-100, 1e100\], got 1e\+200"),
    # small things
    "TruncatedMap eps=True": (
        lambda: hv.TruncatedMap(eps=True, Omega0=1.0, theta_w=2.0),
        r"eps must be a real number, got True",
    ),
    "iterate complex phi": (
        lambda: M.iterate(np.array([0.1 + 1j]), [0.1], 3),
        r"phi0 must be real numbers, got dtype complex128",
    ),
    "iterate record=None": (
        lambda: M.iterate([0.1], [0.1], 3, record=None),
        r"record must be a sequence of keys from \[",
    ),
    "iterate n_steps=2**63-1 orbit": (
        lambda: M.iterate([0.1], [0.1], 2**63 - 1, record=("orbit",)),
        r"n_steps must be <= 2\*\*53",
    ),
    "iterate orbit beyond memory": (
        lambda: M.iterate(np.zeros(100_000), np.zeros(100_000), 10**7, record=("orbit",)),
        r"recording \('orbit',\) for 100000 orbits x 10000000 steps needs [\d.e+]+ GiB, more than half",
    ),
}


# Found by a second, adversarial pass over the whole public API (after the list was fixed).
FM = hv.FlowMap(SYS, 1.0)
CURVE1, CURVE2 = FM.curve, hv.TangentialCurve(hv.Section(SYS, 2.0))  # measured once, outside the timed calls
BAD.update(
    {
        # unbounded work or memory
        "theory 1000 modes": (
            lambda: hv.theory(0.3, hv.OMEGA_G, 2.0, forcing=[1.0] * 1000),
            r"forcing must be a 1-D sequence of 1 to 64 sine coefficients, got shape \(1000,\)",
        ),
        "theory n_grid=1e10": (
            lambda: hv.theory(0.3, hv.OMEGA_G, 2.0, forcing=(1.0, 0.2), n_grid=10**10),
            r"n_grid must be an integer in \[101, 10000000\]",
        ),
        "corner_curves n_phi=1e9": (
            lambda: hv.corner_curves(SEC, [-0.05], n_phi=10**9),
            r"n_phi must be an integer in \[16, 65536\]",
        ),
        # Before: MemoryError from numpy (np.tile of 488 GiB), after the tangential curve was traced.
        "corner_curves 1e6 circles x 65536": (
            lambda: hv.corner_curves(SEC, np.linspace(-0.1, -0.01, 10**6), n_phi=65536),
            r"K \(1000000 circles\) x n_phi \(65536\) = 65536000000 samples, mapped at once; allowed: at most \d+",
        ),
        # Before: MemoryError from numpy copying the broadcast points (an (n, 1) and a (1, n) array
        # are n^2 points), before any check of their number.
        "iterate broadcast 1e12 starts": (
            lambda: M.iterate(np.zeros((10**6, 1)), np.full((1, 10**6), -0.01), 10, record=()),
            r"phi0 \(shape \(1000000, 1\)\) and K0 \(shape \(1, 1000000\)\) broadcast to 1000000000000 points; "
            r"allowed: at most \d+ \(half of this machine's memory at 64 bytes a point\)",
        ),
        "step broadcast 1e12 points": (
            lambda: M.step(np.zeros((10**6, 1)), np.full((1, 10**6), -0.01)),
            r"step: phi \(shape \(1000000, 1\)\) and K \(shape \(1, 1000000\)\) broadcast to 1000000000000 points",
        ),
        "return_map broadcast 1e12 starts": (
            lambda: SEC.return_map(np.zeros((10**6, 1)), np.full((1, 10**6), 0.5)),
            r"theta \(shape \(1000000, 1\)\) and I \(shape \(1, 1000000\)\) broadcast to 1000000000000 points",
        ),
        "to_normal broadcast 1e12 points": (
            lambda: hv.to_normal(SEC, np.zeros((10**6, 1)), np.full((1, 10**6), 0.5)),
            r"theta \(shape \(1000000, 1\)\) and I \(shape \(1, 1000000\)\) broadcast to 1000000000000 points",
        ),
        "forcing_coefficients n_phi=1e7": (
            lambda: hv.forcing_coefficients(SEC, 3, 10**7),
            r"n_phi .* in \[7, 65536\], got 10000000",
        ),
        # silent garbage
        "K_crit Omega0=1e300": (lambda: hv.K_crit(0.3, 2.0, 1e300), r"Omega0 must lie in \[-1e6, 1e6\]"),
        "golden_family eps=1e300": (lambda: hv.golden_family(1e300, 0.5), r"eps = 1e\+300 and c = 0.5 give Omega0"),
        "family complex table": (
            lambda: hv.TruncatedFamily(
                0.3, [-2, -1, -0.5, 0, 1.0], np.full(5, 3.9) + 1j, [1.6] * 5, [1, 0.8, 0.5, 0, 0]
            ),
            r"Omega must be real numbers, got dtype complex128",
        ),
        "family bool table": (
            lambda: hv.TruncatedFamily(0.3, [-2, -1, -0.5, 0, 1.0], [True] * 5, [1.6] * 5, [1, 0.8, 0.5, 0, 0]),
            r"Omega must be real numbers, got dtype bool",
        ),
        "theory forcing='12'": (
            lambda: hv.theory(0.3, hv.OMEGA_G, 2.0, forcing="12"),
            r"forcing must be a sequence of sine coefficients",
        ),
        "forcing_at(1e300)": (lambda: M.forcing_at(1e300), r"phi must be an angle in \[-1e6, 1e6\]"),
        "corner_curves curve of h = 2": (
            lambda: hv.corner_curves(SEC, [-0.05], n_phi=32, bisections=5, curve=CURVE2),
            r"curve must be the TangentialCurve of this section .*it belongs to h = 2.0",
        ),
        "rtol=1e-300": (lambda: hv.FlowMap(SYS, 1.0, rtol=1e-300), r"rtol must lie in \[1e-16, 1\), got 1e-300"),
        "step_rotations of another map": (
            lambda: FM.step_rotations(M.iterate([0.3], [-0.02], 3, record=("orbit", "regions")), 0),
            r"res must be the IterateResult of this FlowMap's iterate",
        ),
        # unclear errors
        "region_mask(NONE)": (lambda: hv.region_mask(hv.Region.NONE), r"Region.NONE \(no return\) is not a region"),
        "exit_regions={NONE}": (
            lambda: M.iterate([0.1], [-0.1], 3, exit_regions={hv.Region.NONE}),
            r"exit_regions: Region.NONE",
        ),
        "birkhoff axis=5": (
            lambda: hv.birkhoff_average([[1.0, 2.0], [3, 4]], axis=5),
            r"axis must be an integer in \[-2, 1\]",
        ),
        "rotation_number(None)": (
            lambda: hv.rotation_number(None),
            r"res must be the IterateResult of a map's iterate",
        ),
        "hovering_area(None)": (
            lambda: hv.hovering_area(None),
            r"m must be a map \(hovering.TruncatedMap, TruncatedFamily or FlowMap\)",
        ),
        "tangential_curve(None)": (lambda: hv.tangential_curve(None, [0.1]), r"sec must be a hovering.Section"),
        "truncated_from_flow(None)": (lambda: hv.truncated_from_flow(None, 0.05), r"cc must be the CornerCurves"),
        "forcing_coefficients n_modes=0": (
            lambda: hv.forcing_coefficients(SEC, 0, 16),
            r"n_modes must be an integer in \[1, 64\], got 0",
        ),
        "k_eps1 shapes": (lambda: M.k_eps1([0.1, 0.2], K0=[1, 2, 3]), r"phi and K0 must have broadcastable shapes"),
        "compare_maps shapes": (
            lambda: hv.compare_maps(SEC, CURVE1, M, [0.1, 0.2], [-0.05, -0.02, 0.0]),
            r"phi and K must have broadcastable shapes, got \(2,\) and \(3,\)",
        ),
        "count('FOO')": (lambda: M.iterate([0.1], [-0.1], 3).count("FOO"), r"status must be one of OK, ESCAPED"),
        "FlowMap.step('a', 0)": (lambda: FM.step("a", 0), r"step: phi must be real numbers"),
        "Section.point('a', 0.3)": (lambda: SEC.point("a", 0.3), r"theta must be real numbers"),
        "hovering_area empty band": (
            lambda: hv.hovering_area(hv.TruncatedMap(eps=0.3, Omega0=3.0, theta_w=2.0, lam=1e300)),
            r"band has no part below K = 0",
        ),
        "FlowMap h=1e300": (lambda: hv.FlowMap(SYS, 1e300), r"h must lie in \(-inf, 1e\+100\], got 1e\+300"),
        # small things
        "iterate n_steps=True": (lambda: M.iterate([0.1], [-0.1], True), r"n_steps must be an integer >= 0, got True"),
        "returns inverse='yes'": (
            lambda: FM.returns(0.3, -0.02, inverse="yes"),
            r"inverse must be True or False, got 'yes'",
        ),
        "keep_points='yes'": (
            lambda: hv.hovering_area(M, n_steps=100, n_samples=100, keep_points="yes"),
            r"keep_points must be True or False",
        ),
        "CustomPotential q_limit=True": (
            lambda: hv.CustomPotential(lambda q: q * q / 2, lambda q: q, q_limit=True),
            r"q_limit must be a float > 0",
        ),
    }
)


def test_enums_and_labels_from_either_side_agree():
    # The two status enums number their members differently (OFF_SECTION = 9 vs 6): count()
    # goes by name, so the "other" enum counts the same orbits instead of silently none.
    r = SEC.return_map([0.1], [-0.3])
    assert r.count(hv.FlowStatus.OFF_SECTION) == r.count(hv.Status.OFF_SECTION) == r.count("off_section") == 1
    f = FM.iterate([0.3], [-100.0], 3)
    assert f.count(hv.Status.OFF_SECTION) == f.count(hv.FlowStatus.OFF_SECTION) == 1
    assert hv.Region.parse("u") is hv.Region.BESIDE  # the itinerary's letter
    s = hv.StepSystem(V1=hv.Harmonic(1.0), V2=hv.Tan(1.4, 0.7), geometry=hv.Geometry.WALL)
    assert s.geometry == "wall"


def test_zero_dimensional_arrays_are_numbers():
    a = hv.TruncatedMap(eps=0.3, Omega0=3.0, theta_w=np.array(2.0))
    assert a.theta_w == 2.0
    assert hv.Harmonic(np.array(2.0)).omega == 2.0


@pytest.mark.parametrize("name", list(BAD))
def test_bad_input_is_a_named_value_error(name):
    call, pattern = BAD[name]
    t0 = time.process_time()
    with pytest.raises(ValueError, match=pattern):
        call()
    # Refused before any long computation: the slowest valid call above (a critical curve) takes
    # seconds of CPU; a refusal takes microseconds. CPU time of this process, not wall time, so
    # other processes loading the machine cannot make the test fail.
    assert time.process_time() - t0 < 0.5, name


def test_family_accepted_wherever_a_map_is():
    # hovering_area and critical_curve took only TruncatedMap (AttributeError 'Omega0' on a family).
    a = hv.hovering_area(FAM, n_samples=400, n_steps=200, rng=1)
    assert 0 <= a.area <= 2 * math.pi * abs(a.box[2] - a.box[3]) and a.error >= 0


def test_exit_regions_label_is_one_region_not_its_characters():
    # "0u" used to be parsed per character ('0' and 'u'); it is J_0u.
    assert hv.region_mask("0u") == 1 << int(hv.Region.BESIDE)
    assert hv.region_mask(["0u", "0"]) == (1 << int(hv.Region.BESIDE)) | (1 << int(hv.Region.ABOVE))


def test_theory_at_resonance_is_nan_not_a_huge_number():
    # At Omega0 = 2 pi, sin(Omega0 / 2) = 0 (to rounding: 1.2e-16): K_crit and rho_crit do not
    # exist (eq:Kcrit divides by it), and the formulas gave ~1e15.
    assert math.isnan(hv.K_crit(0.1, 2.0, 2 * math.pi))
    assert math.isnan(hv.rho_crit(0.1, 2.0, 2 * math.pi, 1.0))
    assert math.isnan(hv.hovering_area_theory(0.1, 2.0, 2 * math.pi))


def test_tan_is_infinite_beyond_its_wall():
    # tan is periodic: V(3.0) used to be the value in the next copy of the well (5.85).
    T = hv.Tan(1.4, 0.7)
    assert T.V(3.0) == math.inf and T.V(-3.0) == math.inf
    assert T.dV(3.0) == math.inf and T.dV(-3.0) == -math.inf
    assert math.isfinite(T.V(0.99 * T.q_limit))


def test_onset_repr_keeps_small_values():
    # std::to_string printed tau1 = 1.7e-7 as 0.000000.
    r = repr(hv.onset_parameters(SYS, 1.0))
    vals = dict(kv.split("=") for kv in r[r.index("(") + 1 : -1].split(", "))
    d = hv.onset_parameters(SYS, 1.0)
    for k, v in vals.items():
        assert float(v) == pytest.approx(getattr(d, k), rel=1e-9), k


def test_generic_action_angle_exact_at_tiny_energies():
    # Turning points are bracketed geometrically from q = 1 down; before, Brent stopped 4 decades
    # above the root for h < 1e-63 and the quadrature failed. Tolerance 1e-13: QAWS's own.
    N = hv.Numerical(hv.Harmonic(1.0))
    for h in (1e-70, 1e-200, 1e-300):
        assert N.turning_points(h)[1] == pytest.approx(math.sqrt(2 * h), rel=1e-14)
        assert N.period(h) == pytest.approx(2 * math.pi, rel=1e-13)


def test_checkpoint_cuts_a_torn_last_line_and_appends_cleanly(tmp_path):
    # A killed process leaves a line without its newline; the next put() was glued onto it and
    # both points were lost on the next read.
    path = tmp_path / "c.jsonl"
    c = Checkpoint(path)
    c.put({"eps": 0.1}, {"area": 1.0})
    with open(path, "a") as f:
        f.write('{"key": {"eps": 0.2}, "row": {"area": 2.')
    again = Checkpoint(path)
    assert again.dropped == 1 and len(again) == 1
    again.put({"eps": 0.2}, {"area": 2.0})
    third = Checkpoint(path)
    assert third.dropped == 0 and len(third) == 2
    assert third.get({"eps": 0.2}) == {"area": 2.0}
    assert [x[:8] for x in path.read_text().splitlines()] == [
        '{"format',
        '{"proven',
        '{"key":{',
        '{"proven',
        '{"key":{',
    ]


@pytest.mark.parametrize(
    "argv,text",
    [
        (["--eps", "nan"], "argument --eps: nan is out of range; allowed: [-0.2, 0.2]"),
        (["--eps", "0.5"], "argument --eps: 0.5 is out of range; allowed: [-0.2, 0.2]"),
        (["--n-orbits", "-3"], "argument --n-orbits: -3 is out of range; allowed: [1, 1000]"),
        (["--n-steps", "-1"], "argument --n-steps: -1 is out of range; allowed: [1, 1000000]"),
        # the old name of --n-steps (deprecated), checked alike
        (["--steps", "-1"], "argument --steps: -1 is out of range; allowed: [1, 1000000]"),
        (["--dpi", "0"], "argument --dpi: 0 is out of range; allowed: [30, 1200]"),
        (["--n-orbits", "2.5"], "argument --n-orbits: '2.5' is not an integer"),
        (["--out", "fig.xyz"], "--out = 'fig.xyz': matplotlib cannot write '.xyz' files"),
    ],
)
def test_demo_cli_refuses_bad_options_before_computing(argv, text, capsys):
    from hovering.__main__ import main

    t0 = time.process_time()
    try:  # argparse's usage errors exit; values it cannot check are reported by main's return value
        rc = main(["demo", *argv])
    except SystemExit as e:
        rc = e.code
    assert rc == 2
    err = capsys.readouterr().err
    assert text in err and "Traceback" not in err
    assert time.process_time() - t0 < 2.0  # CPU seconds (load-proof); the demo itself takes seconds of CPU


def test_scene_cli_refuses_a_bad_out_path(tmp_path, capsys):
    from hovering.__main__ import main

    scene = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "fig_smalleps.toml"
    assert main(["scene", str(scene), "--out", str(tmp_path / "x.nope")]) == 2
    assert "matplotlib cannot write '.nope' files" in capsys.readouterr().err


def test_output_path_names_the_file_savefig_writes(tmp_path):
    # savefig("out/x") writes out/x.png: the summary used to name "out/x".
    from hovering._io.output import output_path

    assert output_path("out", tmp_path / "sub" / "x") == tmp_path / "sub" / "x.png"
    assert output_path("out", tmp_path / "x.pdf") == tmp_path / "x.pdf"
    with pytest.raises(ValueError, match="exists and is not a regular file"):
        output_path("out", _dir_png(tmp_path))


def _dir_png(tmp_path):
    d = tmp_path / "d.png"
    d.mkdir()
    return d


def test_scene_cli_reports_values_only_the_run_can_check_in_one_line(tmp_path, capsys):
    # eps = 1e6 passes the scene schema but puts L1's rotation beyond the band's top: the run
    # refuses it; the CLI used to print a traceback (exit 1) instead of one line (exit 2).
    from hovering.__main__ import main

    src = (Path(__file__).resolve().parents[2] / "examples" / "scenes" / "fig_smalleps.toml").read_text()
    assert "eps = 0.3" in src
    bad = tmp_path / "bad.toml"
    bad.write_text(src.replace("eps = 0.3", "eps = 1e6", 1))
    assert main(["scene", str(bad), "--quick", "--out", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "1e6" in err and "Traceback" not in err
    assert main(["scene", "/dev/zero"]) == 2  # not read forever
    assert "not a regular file" in capsys.readouterr().err


def test_output_path_refuses_what_savefig_would_fail_on(tmp_path):
    from hovering._io.output import output_path

    with pytest.raises(ValueError, match="no NUL byte"):
        output_path("out", str(tmp_path / "a\0b.png"))
    (tmp_path / "plain").write_text("x")
    with pytest.raises(ValueError, match="exists and is not a figure file"):
        output_path("out", tmp_path / "plain")  # would have written plain.png beside it
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        # The verdict must match reality: non-root cannot write here (refused), root can (accepted).
        try:
            (ro / "probe").write_text("")
            (ro / "probe").unlink()
            writable = True
        except OSError:
            writable = False
        if writable:
            assert output_path("out", ro / "x.png") == ro / "x.png"
        else:
            with pytest.raises(ValueError, match="not writable|cannot be written"):
                output_path("out", ro / "x.png")
    finally:
        ro.chmod(0o700)
    assert not list(tmp_path.rglob("*.png"))  # the check leaves no file behind


@pytest.mark.parametrize(
    "m,K_low",
    [(M, -1e-8), (M, -1e-12), (hv.TruncatedMap(eps=0.1, Omega0=1.0, theta_w=1e-10), None)],
    ids=["K_low=-1e-8", "K_low=-1e-12", "theta_w=1e-10 default box"],
)
def test_hovering_area_draws_samples_whatever_the_box(m, K_low):
    # A thin box used to get n_phi ~ sqrt(samples 2 pi / |K_low|) columns: 2.5 M points for
    # samples = 10,000 at K_low = -1e-8, 12.9 TiB for the default box at theta_w = 1e-10. The
    # stratified grid now has at most samples + n_phi <= 2 samples cells.
    a = hv.hovering_area(m, n_steps=16, n_samples=1000, K_low=K_low)
    assert 1000 <= a.n_samples <= 2000
    assert 0 <= a.area <= 2 * math.pi * -a.box[2]
