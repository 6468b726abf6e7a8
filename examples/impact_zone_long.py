"""Do the impact zone's barriers hold for longer runs? (the numbers of docs/impact-zone.md)

The impact_zone scenes give each orbit 1e5 returns (flow) and 2e6 steps (model). Here the upper
layer's orbits get 10x longer: orbits launched at s = 0.95 on the README system at eps = -0.05
must reach s = target to cross the barrier the scenes found at s ~ 0.8, and orbits launched at
s = 0.05 must reach s = 0.5 to cross the lower ones. Prints, per map and direction, the orbits
that crossed, the extreme s reached and the seconds taken.

Run:  python examples/impact_zone_long.py [--flow-orbits 8 --flow-returns 1000000
      --model-orbits 40 --model-steps 20000000 --eps -0.05]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import hovering


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--eps", type=float, default=-0.05)
    ap.add_argument("--flow-orbits", type=int, default=8)
    ap.add_argument("--flow-returns", type=int, default=1_000_000)
    ap.add_argument("--model-orbits", type=int, default=40)
    ap.add_argument("--model-steps", type=int, default=20_000_000)
    ap.add_argument("--down-target", type=float, default=0.7)
    ap.add_argument("--up-target", type=float, default=0.5)
    a = ap.parse_args()

    fm = hovering.FlowMap(hovering.paper.system(eps=a.eps), 1.0)
    tm = fm.truncated(forcing="measured")
    fzone = hovering.impact_zone(fm, n_steps=20_000)
    mzone = hovering.impact_zone(tm, n_steps=20_000, floor=fzone.floor)
    print(f"README system, eps = {a.eps:+g}: {fm!r}")
    for name, m, zone, n_orbits, n_steps in (
        ("flow", fm, fzone, a.flow_orbits, a.flow_returns),
        ("model", tm, mzone, a.model_orbits, a.model_steps),
    ):
        for direction, start, target in (("down", 0.95, a.down_target), ("up", 0.05, a.up_target)):
            t = time.perf_counter()
            r = hovering.transit(
                m, zone, direction, n_orbits=n_orbits, n_steps=n_steps, start_s=start, target_s=target, rng=1
            )
            reach = np.nanmax(r.s_max) if direction == "up" else np.nanmin(r.s_min)
            print(
                f"  {name:5s} {direction:4s} s {start} -> {target}: {int(r.crossed.sum())}/{n_orbits} crossed in "
                f"{n_steps:,} returns each; {'highest' if direction == 'up' else 'lowest'} s reached {reach:.4f} "
                f"({time.perf_counter() - t:.0f} s)"
            )


if __name__ == "__main__":
    main()
