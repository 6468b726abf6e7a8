"""Does the flow hover? |HOV| of the full flow vs its truncated model vs eq:hovsetsize, both signs of eps.

The system of the FlowMap issue: V1 = Harmonic(1), V2 = Tan(1.4, 0.7), bilinear coupling,
qw = (-1, -0.5), h = 1 (Omega0 = 9.8347, so sin(Omega0/2) < 0 and it hovers for eps < 0). For each
eps the same stratified sample points (same seed) are classified by the flow (FlowMap) and by its
truncated model (fm.truncated(): onset-parameter arcs, measured forcing), so the verdicts can be
compared point by point.

    python examples/flow_vs_model.py [--samples 2000] [--steps 2000] [--eps -0.05,0.05,...]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import hovering as hv
from hovering import paper


def system(eps: float) -> hv.StepSystem:
    """The issue's oscillators-step system at coupling eps (:func:`hovering.paper.system`)."""
    return paper.system(eps)


def compare(eps: float, samples: int, steps: int, rtol: float = 1e-10) -> dict:
    """|HOV| of flow and model on the same points, their verdict agreement and the theory."""
    fm = hv.FlowMap(system(eps), h=1.0, rtol=rtol)
    tm = fm.truncated()
    t = time.perf_counter()
    flow = hv.hovering_area(fm, n_steps=steps, n_samples=samples, keep_points=True)
    t_flow = time.perf_counter() - t
    model = hv.hovering_area(tm, n_steps=steps, n_samples=samples, K_low=flow.box[2], keep_points=True)
    th = fm.theory()
    return dict(
        eps=eps,
        flow=flow.area,
        flow_err=flow.error,
        model=model.area,
        model_err=model.error,
        theory=th.area,
        flow_both=flow.area_both_sides,
        model_both=model.area_both_sides,
        agree_both=float(np.mean(flow.both_sides == model.both_sides)),
        agree=float(np.mean(flow.hovering == model.hovering)),
        K_low=flow.box[2],
        b1=th.forcing[0],
        seconds=t_flow,
        unresolved=flow.unresolved,
    )


def main(argv=None) -> None:
    """Print the comparison table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=2000)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--eps", default="-0.05,0.05,-0.1,0.1,-0.2,0.2")
    args = ap.parse_args(argv)
    print("|HOV| as defined (never impacts under eps, impacts under eps = 0), and [its part whose orbits visit both")
    print("J_0 and J_0u: the paper's hovering orbits]; verdicts: the same points classified by flow and model.")
    print(
        f"{'eps':>6} {'flow |HOV|':>16} {'[both sides]':>12} {'model |HOV|':>16} {'[both sides]':>12} "
        f"{'eq:hovsetsize':>13} {'agree':>6} {'[both]':>6} {'K_low':>7} {'b1':>6} {'flow s':>6}"
    )
    for eps in (float(x) for x in args.eps.split(",")):
        r = compare(eps, args.samples, args.steps)
        print(
            f"{r['eps']:6.2f} {r['flow']:8.4f} +- {r['flow_err']:.4f} {r['flow_both']:12.4f} {r['model']:8.4f} +- "
            f"{r['model_err']:.4f} {r['model_both']:12.4f} {r['theory']:13.4f} {100 * r['agree']:5.1f}% "
            f"{100 * r['agree_both']:5.1f}% {r['K_low']:7.4f} {r['b1']:6.3f} {r['seconds']:6.1f}"
        )


if __name__ == "__main__":
    main()
