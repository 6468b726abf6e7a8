"""Command line.

``python -m hovering demo --out FILE.png``: phase portraits of F_eps for +-eps.
``python -m hovering scene SCENE.toml [--out PATH] [--quick]``: one figure of the paper from a scene
file (see :mod:`hovering.scenes` and ``examples/scenes``); prints the numbers shown and the paths.
"""

from __future__ import annotations

import argparse
import sys
import time


def _checked(kind, lo, hi):
    """An argparse type: a finite number of ``kind`` in [lo, hi], or a usage error naming the range."""

    def parse(text):
        try:
            v = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {'an integer' if kind is int else 'a number'}") from None
        if not (lo <= v <= hi):  # also rejects nan
            raise argparse.ArgumentTypeError(f"{text} is out of range; allowed: [{lo}, {hi}]")
        return v

    return parse


def _demo(args) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from . import OMEGA_G, Status, TruncatedMap
    from .plotting import phase_portrait

    fig, axes = plt.subplots(2, 1, figsize=(9, 10), constrained_layout=True)
    t0 = time.perf_counter()
    for ax, eps in zip(axes, (args.eps, -args.eps)):
        m = TruncatedMap(eps=eps, Omega0=OMEGA_G, theta_w=3 * np.pi / 4, tau0=1.0, tau1=0.5, lam=0.5)
        _, res = phase_portrait(m, n_orbits=args.orbits, n_steps=args.steps, ax=ax)
        esc = res.count(Status.ESCAPED)
        print(f"eps={eps:+g}: {args.orbits} orbits x {args.steps} steps, {esc} escaped the band; "
              f"rho_c predicted {m.rho_crit():.4f}")
    fig.suptitle("Truncated map F_eps: orbits from L1, coloured by region (fig:smallepsmany)")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out, dpi=args.dpi)
    print(f"wrote {args.out} in {time.perf_counter() - t0:.2f} s")
    return 0


def _scene(args) -> int:
    import matplotlib

    matplotlib.use("Agg")
    from .scenes import format_summary, load_scene, run_scene

    from ._common import output_path

    try:
        scene = load_scene(args.path)
        out = output_path("--out", args.out) if args.out is not None else None
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    try:
        summary = run_scene(scene, out=out, quick=args.quick)
    except ValueError as e:  # a value only the computation can check (e.g. a K beyond the band's top)
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(format_summary(summary))
    return 0


def main(argv=None) -> int:
    """Entry point of ``python -m hovering``.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status.
    """
    p = argparse.ArgumentParser(prog="python -m hovering", description=__doc__)
    sub = p.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("demo", help="phase portraits of F_eps for +eps and -eps (fig:smallepsmany)")
    d.add_argument("--out", default="hovering_demo.png", help="output PNG (default %(default)s)")
    d.add_argument("--eps", type=_checked(float, 0.0, 10.0), default=0.3, help="|eps| in [0, 10] (default %(default)s)")
    d.add_argument("--orbits", type=_checked(int, 1, 10_000), default=30,
                   help="initial conditions on L1, 1..10000 (default %(default)s)")
    d.add_argument("--steps", type=_checked(int, 1, 10_000_000), default=20000,
                   help="iterates per orbit, 1..1e7 (default %(default)s)")
    d.add_argument("--dpi", type=_checked(int, 30, 1200), default=130, help="PNG resolution, 30..1200 (default %(default)s)")
    sc = sub.add_parser("scene", help="make one figure of the paper from a scene file (examples/scenes/*.toml)")
    sc.add_argument("path", help="scene file (TOML)")
    sc.add_argument("--out", default=None, help="output PNG (default: the scene's 'output'); an NPZ is written next to it")
    sc.add_argument("--quick", action="store_true",
                    help="divide the iterate counts by 50 (a fast check, not the paper's figure)")
    args = p.parse_args(argv)
    if args.cmd == "demo":
        from ._common import output_path

        try:  # before computing: a bad path must not cost the simulation
            args.out = output_path("--out", args.out)
        except ValueError as e:
            p.exit(2, f"python -m hovering demo: error: {e}\n")
        return _demo(args)
    if args.cmd == "scene":
        return _scene(args)
    return 2


if __name__ == "__main__":
    sys.exit(main())
