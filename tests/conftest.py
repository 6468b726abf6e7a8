"""Shared set-up and helpers of the hovering test-suite.

* Selects matplotlib's headless Agg backend before anything imports pyplot.
* Puts this directory on ``sys.path`` so that every test folder imports the shared helpers as
  ``from helpers import numpy_reference`` (``flow_reference``, ``pickle_helpers``) and these as
  ``conftest`` (``from conftest import ...``). The test folders have no conftest.py of their own
  and no ``__init__.py``: test file names are unique across the folders.
* Fixtures of the paper's systems come from :mod:`hovering.paper` (never typed out again).

The helpers never compute a map themselves: they pick test points away from the
discontinuities (using the independent reference) and turn a reference orbit into a rigorous
first-order bound on how far two floating-point implementations of the same map may drift apart.
"""

from __future__ import annotations

import os
import sys

import matplotlib

matplotlib.use("Agg")

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import numpy as np  # noqa: E402
import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

import hovering  # noqa: E402
from helpers import numpy_reference as ref  # noqa: E402
from hovering import paper  # noqa: E402

# Property tests search the same examples on every run, so a run is reproducible on any machine
# (the failures a search found are pinned as @example); HOVERING_FUZZ=1 searches at random (a
# deeper local hunt, with the example database), as test_hypothesis_api's HOVERING_FUZZ=N does.
settings.register_profile("reproducible", derandomize=True, database=None)
settings.register_profile("fuzz", derandomize=False)
settings.load_profile("fuzz" if os.environ.get("HOVERING_FUZZ") else "reproducible")

#: Figure parameters of the paper (fig:smalleps) without eps: hovering.paper's, the one copy.
PAPER = dict(paper.FIGURE)

#: Parameter sets used throughout: the paper's figure for both signs of eps, the largest eps of
#: fig:epsbig, and a case with tau1 < 0 and tau0 < 0 (J_R grows below the tangency circle).
PARAM_SETS = {
    "paper_eps+0.3": dict(eps=paper.EPS_SMALL[0], **PAPER),
    "paper_eps-0.3": dict(eps=paper.EPS_SMALL[1], **PAPER),
    "paper_eps+0.92": dict(eps=paper.EPS_BIG, **PAPER),
    "tau1_negative": dict(eps=0.3, Omega0=1.3, theta_w=2.0, tau0=-0.7, tau1=-0.4, lam=0.7),
}

#: Round-off committed by ONE step of either implementation, in phi and in K.
#: |phi + omega_a| <= pi + |Omega0| + |tau0 K| + 2 pi < 16 for every parameter set and band used
#: here, so one ulp of the sum is <= 3.6e-15; the step rounds omega_a (3-4 terms), the sum, the
#: 2 pi-wrap and sin (1 ulp) - at most ~5 such ulps, hence 1e-14 bounds the local error.
LOCAL_ROUNDOFF = 1e-14


def cdiff(a, b):
    """Circular distance |a - b| on the circle of length 2 pi (angles may differ by 2 pi k)."""
    return np.abs(ref.wrap(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)))


def band_sample(m, n, rng, K_hi=1.5, margin=0.0):
    """n random points: phi uniform on [-pi, pi), K uniform in (lo + margin, K_hi)."""
    lo = m.valid_band()[0]
    phi = rng.uniform(-np.pi, np.pi, n)
    K = rng.uniform(lo + margin, K_hi, n)
    return phi, K


def safe_mask(m, phi, K, margin):
    """Points at least `margin` away from every discontinuity of the truncated map m.

    That is: from the arc ends (reference boundary_distance), from the tangency circle K = 0
    (where the region changes from J_0u to the three arcs) and from the band floor.
    """
    p = m.params
    lo, hi = m.valid_band()
    phi = np.asarray(phi, dtype=float)
    K = np.asarray(K, dtype=float)
    return (ref.boundary_distance(phi, K, p) > margin) & (np.abs(K) > margin) & (K > lo + margin) & (K < hi - margin)


def omega_prime(phi, K, p, regions=None):
    """d omega_a / dK of the truncated map for the region each point lies in (reference regions)."""
    K = np.asarray(K, dtype=float)
    reg = ref.region(phi, K, p) if regions is None else regions
    s = np.sqrt(np.maximum(-K, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        dr = np.where(reg == ref.RIGHT, p["lam"] / s, 0.0)
    return p["tau0"] + np.where(reg == ref.UPPER, p["tau1"], 0.0) + dr


def error_bound(phis, Ks, p, local=LOCAL_ROUNDOFF):
    """First-order bound on the drift between two floating-point evaluations of the same orbit.

    With e_0 = delta_{-1} and e_{j+1} = J_j e_j + delta_j (|delta_j|_inf <= local, J_j the Jacobian
    of F at the reference point x_j), |e_n|_inf <= local * sum_{k=-1}^{n-1} ||J_{n-1} ... J_{k+1}||_inf.
    J = [[1, w'], [c, 1 + c w']] with w' = d omega_a/dK and c = eps cos(phibar).

    Parameters
    ----------
    phis, Ks : ndarray (n_orbits, n + 1)
        Reference orbits (points must stay away from the discontinuities).

    Returns
    -------
    ndarray (n_orbits, n + 1)
        Bound on the max-norm error of each orbit point.
    """
    n = phis.shape[1] - 1
    n_orb = phis.shape[0]
    wp = omega_prime(phis[:, :-1], Ks[:, :-1], p)
    c = p["eps"] * np.cos(phis[:, 1:])
    a11, a12, a21, a22 = np.ones_like(wp), wp, c, 1.0 + c * wp
    acc = np.zeros(phis.shape)
    for k in range(-1, n):
        # error injected into x_{k+1} (k = -1: the initial point) and carried by J_{k+1}, J_{k+2}, ...
        m11, m12, m21, m22 = np.ones(n_orb), np.zeros(n_orb), np.zeros(n_orb), np.ones(n_orb)
        acc[:, k + 1] += 1.0
        for j in range(k + 1, n):
            m11, m12, m21, m22 = (
                a11[:, j] * m11 + a12[:, j] * m21,
                a11[:, j] * m12 + a12[:, j] * m22,
                a21[:, j] * m11 + a22[:, j] * m21,
                a21[:, j] * m12 + a22[:, j] * m22,
            )
            acc[:, j + 1] += np.maximum(np.abs(m11) + np.abs(m12), np.abs(m21) + np.abs(m22))
    return local * acc


def make_map(params, **kw):
    """hovering.TruncatedMap from a parameter dict."""
    return hovering.TruncatedMap(**params, **kw)


@pytest.fixture
def rng():
    """A fixed-seed generator: the suite is deterministic."""
    return np.random.default_rng(20240611)


@pytest.fixture(params=list(PARAM_SETS), ids=list(PARAM_SETS))
def any_map(request):
    """Each parameter set of PARAM_SETS as a TruncatedMap."""
    return make_map(PARAM_SETS[request.param])


class CtrlCOnceStarted:
    """A ``progress(done, total)`` callable that presses Ctrl-C (``_thread.interrupt_main``) the
    first time it sees work done, so the interrupt always lands mid-run whatever the machine's
    speed or load (a timer could fire before the call starts on a loaded machine, or after it ends
    on a fast one). ``fired_at`` is the ``time.perf_counter()`` of the press, for promptness bounds."""

    def __init__(self, after: int = 1):
        self.after, self.fired_at = after, None

    def __call__(self, done, total):
        if self.fired_at is None and done >= self.after:
            import _thread
            import time

            self.fired_at = time.perf_counter()
            _thread.interrupt_main()


#: Upper bound on the time from Ctrl-C to the call's return, for a loaded 2-core machine: the
#: watcher polls every 0.1 s and the core checks its cancel flag every few steps, so an idle
#: machine measures ~0.1-0.2 s; the bound only has to separate "promptly" from "at the end of a
#: run of minutes", so it is generous.
PROMPT = 10.0


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """Every test that runs the C++ executable (it asks for ``sweep_exe``) is end-to-end: the
    default run leaves it out (``-m "not slow and not e2e"`` in pyproject), so a plain
    ``python -m pytest tests`` never builds hovering_sweep; CI and scripts/test.sh run it."""
    for item in items:
        if "sweep_exe" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.e2e)


@pytest.fixture(scope="session")
def sweep_exe():
    """This checkout's hovering_sweep, brought up to date in build/ctest (the directory the README's
    ctest command builds; a no-op after scripts/test.sh), or the executable $HOVERING_SWEEP names."""
    import shutil
    import subprocess
    from pathlib import Path

    if os.environ.get("HOVERING_SWEEP"):
        return os.environ["HOVERING_SWEEP"]
    root = Path(HERE).parent
    cmake = shutil.which("cmake")
    assert cmake, "cmake is needed to build hovering_sweep (scripts/setup.sh installs it)"
    build = root / "build" / "ctest"
    if not (build / "CMakeCache.txt").exists():
        gen = ["-G", "Ninja"] if shutil.which("ninja") else []
        subprocess.run(
            [
                cmake,
                "-S",
                str(root),
                "-B",
                str(build),
                *gen,
                "-DCMAKE_BUILD_TYPE=Release",
                "-DHOVERING_BUILD_TESTS=ON",
                "-DHOVERING_BUILD_APPS=ON",
            ],
            check=True,
            capture_output=True,
            timeout=600,
        )
    r = subprocess.run(
        [cmake, "--build", str(build), "--target", "hovering_sweep"], capture_output=True, text=True, timeout=3600
    )
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return str(build / "hovering_sweep")
