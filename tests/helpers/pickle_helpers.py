"""Module-level callables and classes for the pickling and saving tests.

The standard pickler stores functions and classes by their importable name, so the potentials
defined in Python that the tests pickle (also into spawned worker processes, which import this
module by name: conftest puts tests/ on sys.path, and spawned children inherit it) are built
from what is defined here.
"""

from __future__ import annotations

import functools

import numpy as np

import hovering as hv
from hovering import paper


def quartic_V(q):
    """V = q^2 / 2 + q^4 / 4."""
    return 0.5 * q * q + 0.25 * q**4


def quartic_dV(q):
    """V' = q + q^3."""
    return q + q**3


def scaled_V(q, c):
    """V = c q^2 / 2 (a functools.partial of it is a picklable callable)."""
    return 0.5 * c * q * q


def scaled_dV(q, c):
    """V' = c q."""
    return c * q


class Cosh(hv.Potential):
    """V = a (cosh q - 1): a potential defined as a Python subclass (its instance dict pickles)."""

    def __init__(self, a=1.0):
        super().__init__()
        self.a = a

    def V(self, q):
        return self.a * (np.cosh(q) - 1.0)

    def dV(self, q):
        return self.a * np.sinh(q)

    @property
    def name(self):
        return f"Cosh(a={self.a})"


def quartic():
    """A CustomPotential of module-level functions (picklable by the standard pickler)."""
    return hv.CustomPotential(quartic_V, quartic_dV, name="quartic")


def scaled(c=1.5):
    """A CustomPotential of functools.partial objects of module-level functions."""
    return hv.CustomPotential(functools.partial(scaled_V, c=c), functools.partial(scaled_dV, c=c), name=f"scaled({c})")


def step_chunk(args):
    """``m.step(phi, K)`` of one chunk (for Pool.map)."""
    m, phi, K = args
    return m.step(phi, K)


# ------------------------------------------------------------------ shared objects of both test files

PAPER = paper.FIGURE


def issue_system(eps=-0.05, V1=None, V2=None, geometry="step"):
    """The oscillators-step system of the flow tests (harmonic V1, Tan V2, bilinear coupling)."""
    return paper.system(eps, geometry, V1=V1, V2=V2)


@functools.cache
def maps() -> dict:
    """Every kind of map, with test points (phi, K) inside its band: name -> (map, phi, K)."""
    rng = np.random.default_rng(7)
    n = 300
    phi = rng.uniform(-np.pi, np.pi, n)
    m = hv.TruncatedMap(eps=0.3, **PAPER)
    grid = np.concatenate([-(np.linspace(1.0, 0.0, 40) ** 2), np.linspace(0.05, 1.0, 20)])
    fam = hv.TruncatedFamily.from_map(m, grid, forcing=(1.0, 0.25, -0.1))
    capped = hv.TruncatedMap(eps=-0.2, Omega0=1.3, theta_w=2.0, tau0=-0.7, tau1=-0.4, lam=0.7, K_max=0.4)
    out = {
        "truncated": (m, phi, rng.uniform(-0.6, 0.6, n)),
        "truncated_capped": (capped, phi, rng.uniform(-0.3, 0.15, n)),
        "family": (fam, phi, rng.uniform(-0.5, 0.5, n)),
        "flow_normal": (hv.FlowMap(issue_system(-0.05), h=1.0), phi, rng.uniform(-0.1, 0.05, n)),
        "flow_section": (
            hv.FlowMap(issue_system(0.05), h=1.0, coordinates="section", stepper="rkck", max_impacts=50),
            phi,
            rng.uniform(0.25, 0.45, n),
        ),
        # A potential defined in Python: one thread, ~13x slower per return, so fewer points.
        "flow_custom": (hv.FlowMap(issue_system(-0.05, V1=quartic()), h=1.0), phi[:40], rng.uniform(-0.05, 0.03, 40)),
    }
    return out


@functools.cache
def results() -> dict:
    """One result of every type: name -> result."""
    m, phi, K = maps()["truncated"]
    fam = maps()["family"][0]
    fm, fphi, fK = maps()["flow_normal"]
    sec = fm.section
    out = {
        "iterate_truncated": m.iterate(
            phi[:50], K[:50], 200, record=("orbit", "regions", "rotation", "visited"), exit_regions={"0u", "0"}
        ),
        "iterate_family": fam.iterate(phi[:30], K[:30], 100),
        "iterate_flow": fm.iterate(
            fphi[:12],
            fK[:12],
            6,
            record=(
                "orbit",
                "regions",
                "rotation",
                "visited",
                "section",
                "states",
                "times",
                "energy_error",
                "steps",
                "itinerary",
            ),
            exit_regions={"0u", "0"},
        ),
        "iterate_custom": maps()["flow_custom"][0].iterate(fphi[:4], fK[:4], 3, record=("orbit", "itinerary")),
        "return_map": sec.return_map(fphi[:20], fm.curve.I_tan0 + fK[:20]),
        "flow_steps": fm.returns(fphi[:20], fK[:20]),
        "hovering_area": hv.hovering_area(m, n_steps=400, n_samples=2000, keep_points=True),
        "critical_curve": hv.critical_curve(m, n_steps=2000, n_grid=16),
        "corner_curves": hv.corner_curves(sec, [-0.06, -0.03], curve=fm.curve, n_phi=32, bisections=6),
        "map_comparison": hv.compare_maps(sec, fm.curve, fm.truncated("first_mode"), fphi[:10], fK[:10] - 0.02),
        "theory": m.theory(),
        "theory_family": fam.theory(),
    }
    return out


def same(a, b) -> bool:
    """Exact equality of two result values: arrays by dtype, shape and bits (NaN equal to NaN),
    floats by value (NaN equal to NaN), containers and dataclasses entry by entry; maps by type."""
    import dataclasses
    import math

    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)) or a.dtype != b.dtype or a.shape != b.shape:
            return False
        if a.dtype.kind == "f":
            return bool(np.array_equal(a, b, equal_nan=True))
        return bool(np.array_equal(a, b))
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        return type(a) is type(b) and all(
            (type(getattr(a, f.name)) is type(getattr(b, f.name)))
            if f.name == "map"
            else same(getattr(a, f.name), getattr(b, f.name))
            for f in dataclasses.fields(a)
        )
    if isinstance(a, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict):
        return type(b) is dict and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    return type(a) is type(b) and a == b


def same_steps(m1, m2, phi, K) -> bool:
    """Whether two maps give bit-identical step, step_inverse and region on the points."""
    for f in ("step", "step_inverse"):
        for x, y in zip(getattr(m1, f)(phi, K), getattr(m2, f)(phi, K)):
            if not same(x, y):
                return False
    return same(m1.region(phi, K), m2.region(phi, K))
