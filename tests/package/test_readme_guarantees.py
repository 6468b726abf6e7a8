"""README "Outcomes are values, bad input is an error": every bullet and the tests that keep it
(issue 18). This file holds what no other test kept.

* Bad input is a ValueError before any computation: test_bad_input.py (one case per audited input:
  ::test_bad_input_is_a_named_value_error, bools, complex, strings, ::test_exit_regions_label_is_one_
  region_not_its_characters), test_hypothesis_api.py (no numpy/pybind11 message, no crash), and here
  ::test_the_bullets_example_messages_are_the_apis (the three quoted messages, word for word).
* Size is checked first: test_bad_input.py ("recording ... GiB", "critical tol=0/1e-18",
  ::test_hovering_area_draws_samples_whatever_the_box).
* Per-orbit statuses, NaN only after a stop, one bad orbit never loses the batch:
  test_one_bad_orbit.py (a runaway, an OFF_SECTION, an ESCAPED orbit among good ones, every entry
  point), test_hard_cases.py (CORNER, GRAZING, STEP_LIMIT, NON_FINITE, OUTSIDE_WELL),
  test_exact_flow.py (IMPACT_LIMIT), test_interrupt.py (INTERRUPTED), test_flowmap.py (OFF_SECTION),
  test_truncated_hard.py (ESCAPED), and here ::test_flow_records_are_nan_after_a_stop_and_nowhere_else.
* Values are in range: test_angle_extremes.py (every entry point at +-pi and its ulps),
  test_truncated_hard.py (the 1e6 rotation bound, the band, every OK angle), test_bad_input.py
  (::test_theory_at_resonance_is_nan_not_a_huge_number, ::test_tan_is_infinite_beyond_its_wall),
  test_hypothesis_api.py (inf only for huge inputs), and here
  ::test_angle_of_point_refuses_a_point_off_its_level_by_more_than_1e8.
* Ctrl-C: test_interrupt.py, test_flowmap.py (iterate, return_map, .partial), test_reliability.py
  (a real SIGINT; a system that refuses threads), test_ctrl_c_holds.py (after hundreds of calls, in
  a process that can start no thread, while executor pieces are handed out), test_exit_race.py (a
  long call at exit parks), and here ::test_ctrl_c_stops_hovering_area,
  ::test_ctrl_c_stops_critical_curve, ::test_ctrl_c_stops_a_scene.
* Nothing computed is lost: test_sweeps.py, test_bad_input.py::test_checkpoint_cuts_a_torn_last_line_
  and_appends_cleanly, test_plan.py (resumes across programs), cpp/tests/test_sweep_plan.sh (hovering_sweep).
* Scenes and the CLI: test_bad_input.py (::test_scene_cli_refuses_a_bad_out_path,
  ::test_output_path_names_the_file_savefig_writes, ::test_demo_cli_refuses_bad_options_before_
  computing), test_scenes.py (colours and expressions when the file is read).
"""

from __future__ import annotations

import math
import pathlib
import time

import numpy as np
import pytest

import hovering as hv
from conftest import CtrlCOnceStarted
from hovering import Status

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_the_bullets_example_messages_are_the_apis():
    # "n_threads must be an integer in [0, 4096] (0 = all cores), got 1.7", "phi0[1] must be finite,
    # got nan", "Harmonic: omega must lie in [1e-100, 1e100], got 1e-300": whole messages, as printed.
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
    with pytest.raises(ValueError) as e:
        m.iterate([0.1], [0.1], 3, n_threads=1.7)
    assert str(e.value) == "n_threads must be an integer in [0, 4096] (0 = all cores), got 1.7"
    with pytest.raises(ValueError) as e:
        m.iterate([0.1, math.nan], [0.1, 0.1], 3)
    assert str(e.value) == "phi0[1] must be finite, got nan"
    with pytest.raises(ValueError) as e:
        hv.Harmonic(1e-300)
    assert str(e.value) == "Harmonic: omega must lie in [1e-100, 1e100], got 1e-300"


@pytest.mark.parametrize("V", [hv.Harmonic(1.0), hv.Tan(1.4, 0.7), hv.Numerical(hv.Harmonic(1.0))], ids=repr)
def test_angle_of_point_refuses_a_point_off_its_level_by_more_than_1e8(V):
    # "angle_of_point refuses a point that is not on the level h (1e-8 relative)": a level off by
    # half of that is the point's own level (its angle comes back), by twice that is refused.
    h = 0.5
    q, p = V.point_at(1.0, h)
    assert V.angle_of_point(q, p, h * (1 + 5e-9)) == pytest.approx(1.0, abs=1e-7)
    with pytest.raises(ValueError, match="angle_of_point"):
        V.angle_of_point(q, p, h * (1 + 2e-8))


def test_flow_records_are_nan_after_a_stop_and_nowhere_else():
    # "A stopped orbit keeps its last state; its later records are NaN, and NaN appears nowhere
    # else": the runaway system of test_one_bad_orbit, iterated with every per-return record.
    sys_ = hv.StepSystem(
        V1=hv.Harmonic(0.2), V2=hv.Harmonic(0.2), coupling=hv.Bilinear(), eps=-0.5, qw1=-1, qw2=-2, geometry="wall"
    )
    fm = hv.FlowMap(sys_, 0.3, coordinates="section")
    theta = np.linspace(-math.pi, math.pi, 41)[[0, 1, 12, 33]]
    res = fm.iterate(theta, np.full(4, 0.5), 4, record=("orbit", "section", "states", "times", "energy_error"))
    assert res.status[2] == Status.NON_FINITE and (res.status != Status.OK).sum() >= 1
    for i in range(4):
        n = int(res.steps_done[i])
        for rec in (res.phi, res.K, res.theta, res.I):  # one value per point of the orbit
            assert np.isfinite(rec[i, : n + 1]).all() and np.isnan(rec[i, n + 1 :]).all(), i
        # The state on Sigma_h of each point; OFF_SECTION: a start that has none (nothing at all),
        # or a return to a maximum of q1 that Sigma_h's chart does not hold (the points before it
        # are kept: here orbit 0's first return, at q1 < 0 on this strongly coupled system).
        start_exists = bool(np.isfinite(res.z[i, 0]).all())
        m = n + 1 if start_exists else 0
        assert np.isfinite(res.z[i, :m]).all() and np.isnan(res.z[i, m:]).all()
        for rec in (res.time, res.energy_error):  # one value per return
            assert np.isfinite(rec[i, :n]).all() and np.isnan(rec[i, n:]).all(), i
        # Its last point is kept: the final point is the last recorded one.
        assert res.phi_final[i] == res.phi[i, n] and res.K_final[i] == res.K[i, n]
        assert n == 4 or res.status[i] != Status.OK


def _interrupted(call):
    """Run call(progress) with Ctrl-C (an interrupt of the main thread) pressed once it reports work
    done (CtrlCOnceStarted: mid-run whatever the machine's speed or load, where a timer could fire
    before the call starts or after it ends); the time from the press to the KeyboardInterrupt."""
    press = CtrlCOnceStarted()
    with pytest.raises(KeyboardInterrupt):  # DID NOT RAISE: the interrupt was lost
        call(press)
    return time.perf_counter() - press.fired_at


# Each call below takes seconds (a lost interrupt is a failure, not a hang); stopping must not wait
# for it. The README promises ~0.1 s; the bound is 30 s, generous against a loaded 2-core machine.
def test_ctrl_c_stops_hovering_area():
    m = hv.TruncatedMap(eps=0.3, Omega0=hv.OMEGA_G, theta_w=2.0)
    # ~4 s on 2 idle cores
    assert _interrupted(lambda p: hv.hovering_area(m, n_steps=10**5, n_samples=10**5, n_threads=2, progress=p)) < 30


def test_ctrl_c_stops_critical_curve():
    # On the flow (~10 us per return): 64 x 5000 returns for the grid alone, ~4 s on 2 idle cores.
    s = hv.StepSystem(
        V1=hv.Harmonic(omega=1.0),
        V2=hv.Tan(omega=1.4, alpha=0.7),
        coupling=hv.Bilinear(),
        eps=-0.05,
        qw1=-1.0,
        qw2=-0.5,
        geometry="step",
    )
    fm = hv.FlowMap(s, 1.0)
    assert _interrupted(lambda p: hv.critical_curve(fm, n_steps=5000, n_grid=64, n_threads=2, progress=p)) < 30


def test_ctrl_c_stops_a_scene(tmp_path):
    import tomllib

    from hovering import pipeline, scenes

    # A full |HOV| sweep (4 series x 11 eps) with fewer samples per point: ~7 s on 2 idle cores.
    path = ROOT / "examples" / "scenes" / "fig_hov_vs_eps.toml"
    data = tomllib.loads(path.read_text())
    data["samples"] = 10_000
    scene = scenes.parse_scene(data, path, check_output=False)
    assert _interrupted(lambda p: pipeline.run_scene(scene, out=tmp_path / "hov.png", quick=False, progress=p)) < 30
