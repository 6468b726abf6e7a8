"""Dependencies made for the job (issue 21, item 8): numpy and matplotlib are all that
``pip install hovering`` brings; every other package is an extra, and a feature that needs a
missing one says which extra installs it (before any work), while ``import hovering`` needs none.
"""

from __future__ import annotations

import pathlib
import re
import subprocess
import sys
import tomllib

import numpy as np
import pytest

import hovering
from hovering import paper
from hovering._extras import EXTRAS
from hovering.parallel import Executor

ROOT = pathlib.Path(__file__).resolve().parents[2]
META = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
OPTIONAL = ("dask", "distributed", "xarray", "pandas", "tqdm", "scipy")


def _name(req: str) -> str:
    return re.match(r"[A-Za-z0-9_.-]+", req).group(0).lower()


def test_numpy_and_matplotlib_are_the_only_hard_dependencies():
    assert sorted(_name(r) for r in META["dependencies"]) == ["matplotlib", "numpy"]
    # every extra an error message names exists, and the tests install them all
    extras = META["optional-dependencies"]
    assert set(EXTRAS.values()) <= set(extras)
    assert "hovering[all]" in extras["test"]
    assert set(EXTRAS.values()) <= set(re.search(r"\[(.*)\]", extras["all"][0]).group(1).split(","))


def test_import_hovering_imports_no_optional_package():
    code = f"import sys, hovering; print(sorted(m for m in {OPTIONAL!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True)
    assert out.stdout.strip() == "[]"


def _missing(monkeypatch, *modules):
    """Make ``import module`` fail as if it were not installed (a None entry in sys.modules)."""
    for m in modules:
        monkeypatch.setitem(sys.modules, m, None)


@pytest.mark.parametrize(
    "make",
    [
        lambda: Executor(workers=2, dask=True),
        lambda: Executor(scheduler="tcp://127.0.0.1:1"),
    ],
)
def test_a_dask_run_without_dask_names_the_distributed_extra(monkeypatch, make):
    _missing(monkeypatch, "distributed")
    with pytest.raises(
        ImportError,
        match=r"needs distributed, .* pip install distributed \(hovering's extra 'distributed': pip install '\.\[distributed\]'",
    ):
        make()


def test_a_dask_run_without_dask_fails_before_any_work(monkeypatch):
    _missing(monkeypatch, "distributed")
    calls = []
    with pytest.raises(ImportError, match=r"pip install '\.\[distributed\]'"):
        hovering.hovering_area(
            paper.truncated_map(0.3),
            n_steps=8,
            n_samples=4,
            executor="tcp://127.0.0.1:1",
            progress=lambda d, t: calls.append(d),
        )
    assert calls == []


def test_local_workers_need_no_extra(monkeypatch):
    _missing(monkeypatch, "distributed", "dask")
    m = paper.truncated_map(0.3)
    assert (
        hovering.hovering_area(m, n_steps=40, n_samples=200, executor=2).area
        == hovering.hovering_area(m, n_steps=40, n_samples=200).area
    )


def test_to_xarray_and_to_pandas_without_them_name_their_extras(monkeypatch):
    m = paper.truncated_map(0.3)
    res = m.iterate([0.1], [-0.1], 5)
    zone = hovering.impact_zone(m)
    tr = hovering.transit(m, zone, "up", n_orbits=4, n_steps=10)
    _missing(monkeypatch, "xarray", "pandas")
    with pytest.raises(ImportError, match=r"IterateResult.to_xarray\(\) needs xarray, .* pip install '\.\[xarray\]'"):
        res.to_xarray()
    with pytest.raises(ImportError, match=r"TransitResult.to_pandas\(\) needs pandas, .* pip install '\.\[pandas\]'"):
        tr.to_pandas()


def test_the_scipy_reference_without_scipy_names_the_scipy_extra(monkeypatch):
    from hovering.diagnostics.references import scipy_return_map

    _missing(monkeypatch, "scipy", "scipy.integrate")
    with pytest.raises(ImportError, match=r"needs scipy, .* pip install '\.\[scipy\]'"):
        scipy_return_map(paper.system(-0.1), np.zeros(4), 1e-8)


def test_progress_without_tqdm_is_a_plain_text_bar(monkeypatch, capsys):
    _missing(monkeypatch, "tqdm", "tqdm.auto")
    m = paper.truncated_map(0.3)
    m.iterate(np.zeros(10), np.full(10, 0.1), 100, record=(), progress=True)
    err = capsys.readouterr().err
    assert "TruncatedMap.iterate: 100% (1000/1000 steps)" in err


def test_floors_expand_the_extras_the_test_extra_names():
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import floors
    finally:
        sys.path.pop(0)
    pins = dict(line.split("==") for line in floors.floors(["test"]))
    # every optional package at its declared floor, the package itself never pinned
    for name in ("dask", "distributed", "xarray", "pandas", "tqdm", "scipy", "numpy", "matplotlib", "pytest"):
        assert name in pins, name
    assert "hovering" not in pins
    declared = {_name(r): r.split(">=")[1] for e in META["optional-dependencies"].values() for r in e if ">=" in r}
    assert pins["xarray"] == declared["xarray"] and pins["tqdm"] == declared["tqdm"]
