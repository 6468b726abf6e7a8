"""One barrier of docs/impact-zone.md looked at with the tangent-dynamics tools: the README system
at eps = -0.05, the sharp barrier at s ~ 0.797 below the uppermost chaotic layer, on the flow and
on its truncated model (measured forcing). Prints the numbers docs/barrier-tangent.md quotes.

    python examples/barrier_tangent.py [--quick]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import hovering as hv


def layer_area(m, zone, phi0, K0, n, grid=(256, 128), s_range=(0.6, 1.05)):
    """Area of the (phi, K) cells an orbit visits: a box count of one chaotic layer."""
    r = m.iterate([phi0], [K0], n, record=("orbit",))
    p, k = r.phi[0], r.K[0]
    ok = np.isfinite(p) & np.isfinite(k)
    p, k = p[ok], k[ok]
    klo, khi = np.min(k), np.max(k)
    ip = np.clip(((p + np.pi) / (2 * np.pi) * grid[0]).astype(int), 0, grid[0] - 1)
    ik = np.clip(((k - klo) / (khi - klo) * grid[1]).astype(int), 0, grid[1] - 1)
    cells = np.unique(ip * grid[1] + ik).size
    return cells * (2 * np.pi / grid[0]) * ((khi - klo) / grid[1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    q = 10 if args.quick else 1
    t0 = time.perf_counter()
    fm = hv.paper.flow_map(eps=-0.05, stepper="taylor")
    zone = hv.impact_zone(fm)
    models = {"flow": fm, "model": fm.truncated()}
    print(
        f"zone: floor K {zone.floor.K.min():.4f}..{zone.floor.K.max():.4f}, "
        f"ceiling K {zone.ceiling.K.min():.4f}..{zone.ceiling.K.max():.4f}"
    )
    for name, m in models.items():
        n_scan = (20_000 if name == "flow" else 100_000) // q
        s = np.linspace(0.70, 0.90, 21)
        phi0 = np.asarray(m.L1(0.0)) * np.ones(s.size)
        K0 = zone.K_at(phi0, s)
        phi0 = np.asarray(m.L1(K0))
        res = m.iterate(phi0, K0, n_scan, record=("orbit",), every=1 if name == "flow" else 5)
        cls = hv.classify_orbits(res)
        sv = zone.s(res.phi, res.K)
        print(f"\n{name}: starts on L1 at s = 0.70 .. 0.90, {n_scan} returns each")
        for i in range(s.size):
            print(
                f"  s0 {s[i]:.3f}  {cls.kind[i]:9s} period {cls.period[i]:3d}  s {np.nanmin(sv[i]):.4f}..{np.nanmax(sv[i]):.4f}"
            )
        # the two chaotic layers on either side of the barrier: their exponents and areas
        above = int(np.argmin(np.abs(s - 0.81)))
        below = int(np.argmin(np.abs(s - 0.785)))
        ly = hv.lyapunov(m, phi0[[below, above]], K0[[below, above]], n_scan)
        for tag, j in (("below", 0), ("above", 1)):
            print(
                f"  layer {tag} (s0 {s[[below, above][j]]:.3f}): lambda_1 = {ly.exponents[j, 0]:.4f} "
                f"+- {ly.error[j, 0]:.4f} per return, lambda_1 + lambda_2 = {ly.sum[j]:.1e}"
            )
        A_up = layer_area(m, zone, phi0[above], K0[above], n_scan)
        print(f"  area of the layer above (box count): {A_up:.4g}")
        # periodic orbits near the barrier: periods 1..12, K within the barrier's band
        band = (float(zone.K_at(0.0, 0.76)), float(zone.K_at(0.0, 0.84)))
        for period in range(1, 13):
            found = hv.periodic_orbits(m, period, region=((-np.pi, np.pi), band), n_seeds=2, n_line=24)
            for o in found:
                sv_o = zone.s(o.phi, o.K)
                text = (
                    f"  period {period:2d} {o.winding}/{o.period} {o.stability:18s} R = {o.residue: .4g}  "
                    f"s {np.min(sv_o):.3f}..{np.max(sv_o):.3f}  regions {''.join(map(str, o.regions))}"
                )
                if o.stability == "hyperbolic":
                    fluxes, breaks = [], 0
                    br = {}
                    for kind in ("unstable", "stable"):
                        for b in (1, -1):
                            try:
                                w = hv.manifold(m, o, kind, b, length=0.6, max_points=20_000)
                            except ValueError:
                                continue
                            br[(kind, b)] = w
                            breaks += w.breaks
                    for bu in (1, -1):
                        for bs in (1, -1):
                            if ("unstable", bu) in br and ("stable", bs) in br:
                                try:
                                    L = hv.lobes(br[("unstable", bu)], br[("stable", bs)])
                                    fluxes.append(L.flux)
                                except ValueError:
                                    pass
                    text += f"  branches broken {breaks}x by corner curves"
                    if fluxes:
                        text += f", lobe flux {min(fluxes):.3g}..{max(fluxes):.3g} per return"
                print(text)
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
