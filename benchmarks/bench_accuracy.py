"""Work-precision diagrams of the README: the flow (Harmonic(1) + Tan(1.4, 0.7), qw = (-1, -0.5), h = 1;
wall and step geometries; eps = 0 and 0.05) and the truncated map, measured in one run.

Prints each table (hovering.work_precision), the ratios that matter (time per return at matched
error between steppers, the exact flow against rk8pd at rtol 1e-13, the long-orbit growth
error(1e4) / error(1)), and writes the diagrams to docs/accuracy_*.png.

Every stepper of the default diagram (taylor, rk8pd, rkck, rkf45, msadams) and, when heyoka.py is
installed, its Taylor integrator's curve.

Run: python benchmarks/bench_accuracy.py [--quick]   (about 10 minutes with heyoka.py installed, 6 without; --quick: 40 s)
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402

import hovering  # noqa: E402
from hovering import paper  # noqa: E402
from hovering._io.output import savefig  # noqa: E402  (atomic: a killed run leaves the old docs PNG)
from hovering.diagnostics import exact_available  # noqa: E402

DOCS = Path(__file__).resolve().parents[1] / "docs"


def system(eps, geometry):
    return paper.system(eps, geometry)


def matched(wp, a, b, error):
    """seconds(b) / seconds(a) of the fastest settings of methods a and b that reach error."""
    ra = [r for r in wp.table if r["method"] == a and r["error"] <= error]
    rb = [r for r in wp.table if r["method"] == b and r["error"] <= error]
    if not ra or not rb:
        return None
    return min(r["seconds"] for r in rb) / min(r["seconds"] for r in ra)


def exact_speed(sec, n=20000):
    """(us per return of exact, of rk8pd at rtol = atol = 1e-13, max state distance between them), on
    precomputed points of Sigma_h (only the returns are timed, as in bench_exact.py)."""
    from hovering import _core
    from hovering.flow import flow_options

    rng = np.random.default_rng(5)
    z = sec.point(rng.uniform(-np.pi, np.pi, n), rng.uniform(0.05, 0.4, n))
    out = {}
    for name, opts in (("exact", flow_options(stepper="exact")), ("rk8pd", flow_options(rtol=1e-13, atol=1e-13))):
        best = np.inf
        for _ in range(3):
            t0 = time.perf_counter()
            r = _core.flow.return_maps(sec.sys.core, z, opts, 1, 0.0, 0, None)
            best = min(best, time.perf_counter() - t0)
        out[name] = (best / n, r)
    a, b = out["exact"][1], out["rk8pd"][1]
    ok = (a["status"] == 0) & (b["status"] == 0)
    return out["exact"][0], out["rk8pd"][0], float(np.max(np.abs(a["z"][ok] - b["z"][ok])))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    DOCS.mkdir(exist_ok=True)
    returns = (1, 100) if args.quick else (1, 100, 10_000)
    import importlib.util

    # heyoka.py's curve where it is installed (its Python-side cost per propagate_until included).
    external = ("heyoka",) if importlib.util.find_spec("heyoka") else ()
    for eps, geometry in ((0.0, "wall"), (0.0, "step"), (0.05, "wall"), (0.05, "step")):
        sec = hovering.Section(system(eps, geometry), 1.0)
        t0 = time.perf_counter()
        wp = hovering.work_precision(sec, quick=args.quick, returns=returns, external=external)
        print(f"\n## {geometry}, eps = {eps}  ({time.perf_counter() - t0:.0f} s)\n")
        print(wp.format())
        for err in (1e-6, 1e-9, 1e-12):
            for other in ("rkck", "rkf45", "msadams", "taylor", "heyoka.py Taylor"):
                r = matched(wp, "rk8pd", other, err)
                if r is not None:
                    print(f"  error <= {err:g}: {other} / rk8pd time per return = {r:.2f}")
            r = matched(wp, "taylor", "heyoka.py Taylor", err)
            if r is not None:
                print(f"  error <= {err:g}: heyoka.py / taylor time per return = {r:.2f}")
        for row in wp.table:
            ea = row.get("error_after", {})
            if returns[-1] in ea and ea[1] > 0:
                print(
                    f"  {row['method']} {row['tolerance']:.0e}: error({returns[-1]}) / error(1) = "
                    f"{ea[returns[-1]] / ea[1]:.3g}  (m^2 = {returns[-1] ** 2:.0e})"
                )
        if exact_available(sec):
            te, tr, d = exact_speed(sec)
            print(
                f"  exact: {1e6 * te:.2f} us per return; rk8pd at rtol 1e-13: {1e6 * tr:.2f} us; "
                f"ratio {tr / te:.0f}x; max distance {d:.2g}"
            )
        savefig(wp.plot(), DOCS / f"accuracy_{geometry}_eps{eps:g}.png", dpi=90)
    m = paper.truncated_map(0.05)
    wp = hovering.work_precision(m, quick=args.quick)
    print("\n## truncated map (rotation number)\n")
    print(wp.format())
    savefig(wp.plot(), DOCS / "accuracy_truncated.png", dpi=90)


if __name__ == "__main__":
    main()
