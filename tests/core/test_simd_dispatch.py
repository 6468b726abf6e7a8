"""The run-time choice of the truncated map's SIMD lane kernel (a portable build has one per level).

Each level this CPU runs is forced in turn (``_core.truncated.set_simd_level``, what
``HOVERING_SIMD`` sets at start-up) and checked against the kernels' documented promises:

* ``simd_width()`` / ``simd_level()`` report the forced level (sse2: 2 doubles, avx2: 4, avx512: 8);
* one step's phi and region are those of ``step()`` / ``region()`` bit for bit (no sin enters them);
* one step's K is within the two sins' error of ``step()``'s (SLEEF's vector sin vs libm's);
* a few steps agree with the scalar kernel to 1e-12, and thread count changes nothing.

A level this CPU does not run, or that no build has, is a ValueError naming it and the choices
(from ``HOVERING_SIMD``: at the first use of a kernel, before any computation).
The C++ side (every level vs step() at the arc starts) is in cpp/tests/test_truncated_hard.cpp and
test_iterate.cpp; that the rest of the core holds no AVX instruction, in cpp/tests/test_portable.sh.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import hovering as hv
from hovering import paper
from hovering._core import truncated as core

WIDTH = {"sse2": 2, "avx2": 4, "avx512": 8}


@pytest.fixture
def restore_level():
    """Put back the level selected before the test (the module's state is process-wide)."""
    before = core.simd_level()
    yield
    core.set_simd_level(before)


def _maps():
    m = paper.truncated_map(0.3)
    F = paper.FIGURE
    Kg = np.linspace(-1.5, 1.0, 41)
    fam = hv.TruncatedFamily(
        0.2,
        Kg,
        lambda K: F["Omega0"] + F["tau0"] * K,
        lambda K: 2 * (np.pi - F["theta_w"]) + F["tau1"] * K,
        lambda K: 2 * F["lam"] * np.sqrt(np.maximum(-K, 0.0)),
        forcing=(1.0, 0.3, 0.1),
    )
    # each with |eps| sum |b_k|, the largest kick a sin error is scaled by
    return {"TruncatedMap": (m, 0.3), "TruncatedFamily": (fam, 0.2 * 1.4)}


def _points(m, n=4000, seed=11):
    """Random points of the band below K = 1, plus the arc starts and their neighbours (the exact path)."""
    rng = np.random.default_rng(seed)
    phi = rng.uniform(-np.pi, np.pi, n)
    K = rng.uniform(-1.2, 0.9, n)
    Ks = np.array([-0.01, -0.5, -1.0])
    a = m.arcs(Ks)
    starts = np.concatenate([a["start_1"], a["start_R"], a["start_0"]])
    heights = np.tile(Ks, 3)
    extra_phi, extra_K = [], []
    for d in (0.0, 1e-300, -1e-300, 1e-16, -1e-16, 1e-9, -1e-9):
        extra_phi.append(hv.wrap(starts + d))
        extra_K.append(heights)
    return np.concatenate([phi, *extra_phi]), np.concatenate([K, *extra_K])


def test_auto_selects_the_widest_level_this_cpu_runs(restore_level):
    levels = core.simd_levels()
    assert levels, "no SIMD level"
    widths = [WIDTH.get(x, 0) for x in levels]
    assert widths == sorted(widths), f"levels not narrowest first: {levels}"
    core.set_simd_level("auto")
    assert core.simd_level() == levels[-1]
    assert hv.simd_width() == core.simd_width()
    if levels[-1] in WIDTH:
        assert hv.simd_width() == WIDTH[levels[-1]]


@pytest.mark.parametrize("level", ["sse2", "avx2", "avx512"])
@pytest.mark.parametrize("which", ["TruncatedMap", "TruncatedFamily"])
@pytest.mark.parametrize("sin_ulp", [1.0, 3.5])
def test_each_level_this_cpu_runs_keeps_the_kernel_promises(level, which, sin_ulp, restore_level):
    if level not in core.simd_levels():
        # Not run here: forcing it is a clear error, and the selection stays as it was.
        before = core.simd_level()
        # the message names the level and the allowed ones (a native build has one level only)
        with pytest.raises(ValueError, match=rf"('{level}'.*lacks|must be one of auto.*got '{level}')"):
            core.set_simd_level(level)
        assert core.simd_level() == before
        return
    core.set_simd_level(level)
    assert core.simd_level() == level
    assert hv.simd_width() == WIDTH[level]
    assert hv.simd_is_avx2() == (WIDTH[level] >= 4)

    m, kick = _maps()[which]
    phi, K = _points(m)
    r = m.iterate(phi, K, 1, record=("regions",), sin_ulp=sin_ulp)
    inside = r.status != hv.Status.ESCAPED
    assert inside.sum() > 3500  # the points checked: most of the band's
    p1, k1 = m.step(phi[inside], K[inside])
    # phi and the region: the same operations on the same doubles, bit for bit.
    np.testing.assert_array_equal(r.phi_final[inside], p1)
    np.testing.assert_array_equal(r.region[inside, 0], m.region(phi[inside], K[inside]))
    # K + eps f(phi1): SLEEF's sin (sin_ulp) and libm's (< 1 ulp) differ by at most sin_ulp + 1 ulp
    # of f's terms, each scaled by |eps b_k| <= |eps| sum |b_k|; a rounding of the products and the
    # sum on each side adds at most 2 ulp of |K1| + |eps| sum |b_k|.
    tol = (2 * (sin_ulp + 1) + 4) * np.spacing(np.abs(k1) + kick)
    assert np.all(np.abs(r.K_final[inside] - k1) <= tol), np.max(np.abs(r.K_final[inside] - k1) / tol)


@pytest.mark.parametrize("level", ["sse2", "avx2", "avx512"])
def test_each_level_follows_the_scalar_kernel_over_a_few_steps(level, restore_level):
    if level not in core.simd_levels():
        with pytest.raises(ValueError, match=level):
            core.set_simd_level(level)
        return
    core.set_simd_level(level)
    m = paper.truncated_map(0.3)
    rng = np.random.default_rng(3)
    phi = rng.uniform(-np.pi, np.pi, 1003)  # not a multiple of any lane block
    K = rng.uniform(-0.3, 0.3, 1003)
    s = m.iterate(phi, K, 5, record=("regions",), kernel="scalar", n_threads=1)
    v1 = m.iterate(phi, K, 5, record=("regions",), n_threads=1)
    v2 = m.iterate(phi, K, 5, record=("regions",), n_threads=2)
    np.testing.assert_array_equal(v1.phi_final, v2.phi_final)
    np.testing.assert_array_equal(v1.K_final, v2.K_final)
    # Per step the sins differ by ~1 ulp (~1e-16 in K); 5 steps of a map with O(1) derivatives
    # grow that to ~1e-15 at most; 1e-12 leaves room and would still catch a wrong packet.
    assert np.max(np.abs(hv.wrap(v1.phi_final - s.phi_final))) < 1e-12
    assert np.max(np.abs(v1.K_final - s.K_final)) < 1e-12
    np.testing.assert_array_equal(v1.region, s.region)
    np.testing.assert_array_equal(v1.status, s.status)


def test_unknown_level_names_the_value_and_the_choices(restore_level):
    before = core.simd_level()
    with pytest.raises(ValueError) as e:
        core.set_simd_level("avx1024")
    text = str(e.value)
    assert "'avx1024'" in text and "auto" in text
    for level in core.simd_levels():
        assert level in text
    assert core.simd_level() == before


def _python(code: str, **env):
    full = dict(os.environ)
    full.pop("HOVERING_SIMD", None)
    full.update(env)
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, env=full, timeout=300
    )


def test_environment_variable_forces_the_level_at_start_up(restore_level):
    for level in (core.simd_levels()[0], "auto"):
        r = _python(
            "import hovering as hv; from hovering._core import truncated as c; print(c.simd_level(), hv.simd_width())",
            HOVERING_SIMD=level,
        )
        assert r.returncode == 0, r.stderr
        core.set_simd_level(level)  # the same choice, made here
        assert r.stdout.split() == [core.simd_level(), str(hv.simd_width())]


def test_bad_environment_variable_is_a_clear_error_at_first_use():
    # The core reads HOVERING_SIMD at its first use of a kernel (``import hovering`` alone loads no
    # core): a level that cannot be had stops there, before any computation, with the value and the
    # choices. The first iteration and the width query both say it.
    for value, needle in (("bogus", "must be one of auto"), ("avx1024", "must be one of auto")):
        first_use = "m = hovering.TruncatedMap(eps=0.3, Omega0=1.0, theta_w=2.0); m.iterate([0.0], [0.1], 10)"
        r = _python(f"import hovering; print('imported', flush=True); {first_use}", HOVERING_SIMD=value)
        assert r.stdout.strip() == "imported"  # a light import, then the error at the first use
        assert r.returncode == 1
        last = r.stderr.strip().splitlines()[-1]
        assert last.startswith(f"ValueError: HOVERING_SIMD {needle}") and f"got '{value}'" in last, last
        r = _python("import hovering; hovering.simd_width()", HOVERING_SIMD=value)
        assert r.returncode == 1
        last = r.stderr.strip().splitlines()[-1]
        assert last.startswith(f"ValueError: HOVERING_SIMD {needle}") and f"got '{value}'" in last, last
        for level in core.simd_levels():
            assert level in last
