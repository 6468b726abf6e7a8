"""One name per concept across the public API (issue "habits"), and ``rng=`` as SPEC 7 has it.

* Every public function and method takes the one name of a concept: a signature holding a name
  listed in ``OLD_NAMES`` (the twin of another, kept only as a deprecated keyword) fails the scan,
  so a new twin is caught where it is introduced.
* An old keyword still works: it warns (DeprecationWarning naming the new one, attributed to the
  caller's line) and gives the same result as the new one; both at once are a TypeError.
* ``rng`` takes None, an int or a numpy Generator: an int is the old ``seed`` (same result), a
  Generator gives one seed (drawn once, recorded on the result, which reproduces the run), None a
  fresh one; anything else is an error naming the value and what is allowed.
"""

from __future__ import annotations

import inspect
import json
import warnings
import zipfile

import numpy as np
import pytest

import hovering
from hovering import paper

#: old name -> the one name of its concept. A public signature must not take an old name: the old
#: spelling is accepted through hovering._deprecated.renamed_keywords only (not in the signature).
OLD_NAMES = {
    "samples": "n_samples",  # hovering_area(samples=) vs compare_hovering(n_samples=), HoveringArea.n_samples
    "seed": "rng",  # SPEC 7
    "random_state": "rng",  # scikit-learn's spelling of the same
    "grid": "n_grid",  # critical_curve(grid=) vs theory(n_grid=)
    "iterations": "bisections",  # tangential_curve(iterations=) vs corner_curves(bisections=)
    "n_iter": "n_steps",
    "threads": "n_threads",
    "k_range": "K_range",
    "n_sample": "n_samples",
}

#: (callable, name) that may keep an old name: a result's record of the seed a run used is an int
#: (what ``rng=`` takes back), named as scene files and provenance name it, not an rng argument.
RECORDS = {("HoveringArea", "seed")}

M = hovering.TruncatedMap(eps=0.2, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)


def _public_callables():
    """(qualified name, callable) of every public function, class and method of ``hovering.__all__``
    (methods inherited from mixins included: ``TruncatedMap.hovers`` is MapAnalyses')."""
    out = []
    for name in hovering.__all__:
        obj = getattr(hovering, name)
        if inspect.ismodule(obj):
            continue
        if inspect.isclass(obj):
            out.append((name, obj))
            for attr in dir(obj):
                if attr.startswith("_"):
                    continue
                try:
                    v = inspect.getattr_static(obj, attr)
                except AttributeError:
                    continue
                if isinstance(v, (staticmethod, classmethod)):
                    v = v.__func__
                if callable(v) and not isinstance(v, type):
                    out.append((f"{name}.{attr}", v))
        elif callable(obj):
            out.append((name, obj))
    return out


def _parameters(fn) -> list:
    try:
        return list(inspect.signature(fn).parameters)
    except (TypeError, ValueError):  # a builtin without a signature
        return []


def _twins(fn, qualname: str = "") -> list:
    return sorted(n for n in set(_parameters(fn)) & set(OLD_NAMES) if (qualname, n) not in RECORDS)


def test_no_public_signature_takes_an_old_name_of_a_concept():
    found = {q: _twins(fn, q) for q, fn in _public_callables() if _twins(fn, q)}
    assert not found, (
        f"{found}: these names are old twins of {[OLD_NAMES[n] for names in found.values() for n in names]}; "
        "use the one name (docs/guide/outcomes.md, 'One name per concept'), or accept the old one with "
        "hovering._deprecated.renamed_keywords"
    )


def test_the_scan_sees_the_signatures_and_would_catch_a_twin():
    seen = dict(_public_callables())
    # the renamed functions and the inherited methods are scanned under their new names...
    assert "TruncatedMap.hovers" in seen
    assert {"n_samples", "rng"} <= set(_parameters(seen["hovering_area"]))
    assert "n_grid" in _parameters(seen["critical_curve"]) and "bisections" in _parameters(seen["tangential_curve"])
    assert "rng" in _parameters(seen["transit"]) and "rng" in _parameters(seen["work_precision"])

    # ...and a function taking a twin is flagged (the scan is not vacuous)
    def twin(m, n_steps=10, samples=100, seed=0):
        """A new function that took the old names."""

    assert _twins(twin) == ["samples", "seed"]


def test_every_renamed_keyword_is_a_listed_twin():
    # what renamed_keywords accepts is what the scan forbids: the two lists cannot drift apart
    renamed = {}
    for q, fn in _public_callables():
        for old, new in getattr(fn, "__renamed_keywords__", {}).items():
            renamed[(q, old)] = new
    assert renamed, "no function declares renamed keywords: the scan lost them"
    for (q, old), new in renamed.items():
        assert OLD_NAMES.get(old) == new, (q, old, new)
        assert new in _parameters(dict(_public_callables())[q]), (q, new)


# ------------------------------------------------------------------------------------------------
# The old keywords: same result, a warning naming the new one, both at once refused


def _old_and_new(fn, old: dict, new: dict):
    """fn(**old) under a recorded DeprecationWarning, fn(**new) with warnings as errors."""
    with pytest.warns(DeprecationWarning) as rec:
        got_old = fn(**old)
    got_new = fn(**new)
    return got_old, got_new, rec


def test_hovering_area_old_names_warn_and_give_the_same_area():
    old, new, rec = _old_and_new(
        lambda **kw: hovering.hovering_area(M, n_steps=200, **kw), dict(samples=500, seed=4), dict(n_samples=500, rng=4)
    )
    assert old.area == new.area and old.n_samples == new.n_samples and old.seed == new.seed == 4
    texts = [str(w.message) for w in rec]
    assert any("hovering_area(samples=...)" in t and "use hovering_area(n_samples=...)" in t for t in texts), texts
    assert any("hovering_area(seed=...)" in t and "use hovering_area(rng=...)" in t for t in texts), texts
    assert all(w.filename == __file__ for w in rec)  # the user's line, not the package's


def test_the_old_keyword_the_deprecated_method_and_positional_calls_keep_working():
    with pytest.warns(DeprecationWarning, match=r"hovering_area\(samples=\.\.\.\).*n_samples"):
        old = hovering.hovering_area(M, n_steps=200, samples=500)
    # The method is the function now (analyses are free functions of a map): it warns and calls it.
    with pytest.warns(
        DeprecationWarning,
        match=r"TruncatedMap\.hovering_area\(\) is deprecated .*use hovering\.hovering_area\(m, \.\.\.\)",
    ):
        method = M.hovering_area(200, 500)
    assert old.area == hovering.hovering_area(M, 200, 500).area == method.area


def test_both_names_at_once_are_a_type_error():
    for call in (
        lambda: hovering.hovering_area(M, n_steps=200, samples=500, n_samples=500),
        lambda: hovering.hovering_area(M, n_steps=200, seed=1, rng=1),
        lambda: hovering.hovering_area(M, n_steps=200, samples=500, n_samples=500),
        lambda: hovering.critical_curve(M, grid=8, n_grid=8),
    ):
        with pytest.raises(
            TypeError, match=r"got both (samples|seed|grid)= \(deprecated\) and (n_samples|rng|n_grid)="
        ):
            call()


def test_critical_curve_grid_is_n_grid():
    kw = dict(n_steps=600, tol=1e-3)
    with pytest.warns(DeprecationWarning, match=r"critical_curve\(grid=\.\.\.\).*critical_curve\(n_grid=\.\.\.\)"):
        old = hovering.critical_curve(M, grid=8, **kw)
    assert old.K0 == hovering.critical_curve(M, n_grid=8, **kw).K0
    # impact_zone passes its keywords on: the old name still reaches critical_curve (and warns)
    with pytest.warns(DeprecationWarning, match=r"n_grid"):
        z_old = hovering.impact_zone(M, n_steps=600, floor=-0.3, grid=8, tol=1e-3)
    z_new = hovering.impact_zone(M, n_steps=600, floor=-0.3, n_grid=8, tol=1e-3)
    np.testing.assert_array_equal(z_old.ceiling.K, z_new.ceiling.K)


def test_tangential_curve_iterations_is_bisections():
    sec = hovering.Section(paper.system(0.05), 1.0)
    theta = np.array([-1.0, 0.5])
    with pytest.warns(DeprecationWarning, match=r"tangential_curve\(iterations=\.\.\.\).*bisections"):
        old = hovering.tangential_curve(sec, theta, iterations=12)
    np.testing.assert_array_equal(old, hovering.tangential_curve(sec, theta, bisections=12))
    with pytest.raises(ValueError, match=r"bisections must be an integer in \[1, 200\], got 0"):
        hovering.tangential_curve(sec, theta, bisections=0)


def test_transit_and_work_precision_seed_is_rng():
    zone = hovering.impact_zone(M, n_steps=600, floor=-0.3, tol=1e-3)
    kw = dict(n_orbits=6, n_steps=300)
    with pytest.warns(DeprecationWarning, match=r"transit\(seed=\.\.\.\).*transit\(rng=\.\.\.\)"):
        old = hovering.transit(M, zone, seed=9, **kw)
    new = hovering.transit(M, zone, rng=9, **kw)
    np.testing.assert_array_equal(old.phi0, new.phi0)
    assert old.seed == new.seed == 9
    # the old stream: numpy.random.default_rng(seed), one uniform per orbit's cell
    jitter = np.random.default_rng(9).random(6)
    np.testing.assert_allclose(new.phi0, -np.pi + 2 * np.pi * (np.arange(6) + jitter) / 6)

    wp = dict(quantity="hovering_area", tolerances=[(16, 8), (32, 8)], repeat=1)
    with pytest.warns(DeprecationWarning, match=r"work_precision\(seed=\.\.\.\)"):
        a = hovering.work_precision(M, seed=2, **wp)
    b = hovering.work_precision(M, rng=2, **wp)
    assert [r["area"] for r in a.rows] == [r["area"] for r in b.rows]


# ------------------------------------------------------------------------------------------------
# rng: None, an int or a Generator


def test_rng_int_and_generator_give_the_old_seed_result():
    kw = dict(n_steps=200, n_samples=600, keep_points=True)
    with pytest.warns(DeprecationWarning):
        by_seed = hovering.hovering_area(M, seed=11, **kw)
    by_int = hovering.hovering_area(M, rng=11, **kw)
    np.testing.assert_array_equal(by_seed.phi, by_int.phi)
    assert by_seed.area == by_int.area and by_int.seed == 11
    # a Generator gives one seed, drawn once: the run is the old seed= run with that seed
    drawn = int(np.random.default_rng(5).integers(0, 2**63 - 1, endpoint=True))
    by_gen = hovering.hovering_area(M, rng=np.random.default_rng(5), **kw)
    with pytest.warns(DeprecationWarning):
        by_drawn_seed = hovering.hovering_area(M, seed=drawn, **kw)
    assert by_gen.seed == drawn
    np.testing.assert_array_equal(by_gen.phi, by_drawn_seed.phi)
    assert by_gen.area == by_drawn_seed.area
    # the Generator advances: a second call on it draws other samples
    g = np.random.default_rng(5)
    first, second = hovering.hovering_area(M, rng=g, **kw), hovering.hovering_area(M, rng=g, **kw)
    assert first.seed != second.seed and not np.array_equal(first.phi, second.phi)


def test_rng_none_is_fresh_and_recorded(tmp_path):
    kw = dict(n_steps=200, n_samples=400, keep_points=True)
    a, b = hovering.hovering_area(M, rng=None, **kw), hovering.hovering_area(M, rng=None, **kw)
    assert isinstance(a.seed, int) and 0 <= a.seed <= 2**63 - 1 and a.seed != b.seed
    again = hovering.hovering_area(M, rng=a.seed, **kw)  # the recorded seed reproduces the run
    np.testing.assert_array_equal(a.phi, again.phi)
    # the seed travels with a saved result: its field and the file's provenance
    path = hovering.save(a, tmp_path / "a.npz")
    with zipfile.ZipFile(path) as z, z.open("__meta__.npy") as f:
        doc = json.loads(str(np.lib.format.read_array(f)))
    assert hovering.load(path).seed == a.seed and doc["provenance"]["seed"] == a.seed


def test_the_default_rng_is_seed_zero_as_before():
    # rng=0 by default (as seed=0 was): the same call gives the same numbers, unlike rng=None
    kw = dict(n_steps=200, n_samples=400)
    assert hovering.hovering_area(M, **kw).seed == 0
    assert hovering.hovering_area(M, **kw).area == hovering.hovering_area(M, rng=0, **kw).area


@pytest.mark.parametrize(
    "bad,error,text",
    [
        (-1, ValueError, r"rng must be an integer seed in \[0, 9223372036854775807\].*got -1"),
        (2**63, ValueError, r"rng must be an integer seed in \[0, 9223372036854775807\].*got 9223372036854775808"),
        (1.5, TypeError, r"rng must be None, an integer seed in \[0, \d+\] or a numpy\.random\.Generator.*got 1\.5"),
        ("7", TypeError, r"rng must be None, an integer seed .* got '7' of type str"),
        (True, TypeError, r"rng must be None, an integer seed .* got True of type bool"),
        (np.random.RandomState(0), TypeError, r"rng must be .*numpy\.random\.Generator.* of type RandomState"),
        (np.random.SeedSequence(3), TypeError, r"rng must be .* of type SeedSequence"),
    ],
)
def test_bad_rng_names_the_value_and_what_is_allowed(bad, error, text):
    zone = hovering.ImpactZone(
        ceiling=hovering.Curve.constant(-0.05), floor=hovering.Curve.constant(-0.3), floor_kind="given", raised=False
    )
    for call in (
        lambda: hovering.hovering_area(M, n_steps=200, n_samples=100, rng=bad),
        lambda: hovering.transit(M, zone, n_orbits=4, n_steps=10, rng=bad),
        lambda: hovering.work_precision(M, quantity="hovering_area", tolerances=[(16, 8), (32, 8)], rng=bad),
    ):
        with pytest.raises(error, match=text):
            call()


def test_numpy_integers_and_zero_d_arrays_are_seeds():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a = hovering.hovering_area(M, n_steps=200, n_samples=300, rng=np.int64(3))
        b = hovering.hovering_area(M, n_steps=200, n_samples=300, rng=np.array(3, dtype=np.uint32))
    assert a.seed == b.seed == 3 and a.area == b.area
