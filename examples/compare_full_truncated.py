"""Full return map of the oscillators-step flow vs the truncated map, in normal coordinates.

For eps in a list and circles K = const, maps the same points (phi, K) with
  * the full return map: (phi, K) -> (theta, I) (eq:kphiinvdef, tangential curve from the flow)
    -> GSL impact flow -> back to (phi, K) (eq:kphidef);
  * the truncated family F_{eps,0} (eq:trunceps1eps2) with the onset parameters of the same system
    (sec:parametersdef) and the measured forcing f (eq:defoff) as sine series;
and prints the largest differences, to compare with the remainders of thm:returnmap
(G_K = O(eps K) in J_0, G_phi = O(eps) + higher order in K).

Run: python examples/compare_full_truncated.py
"""

from __future__ import annotations

import numpy as np

import hovering
from hovering import StepSystem, TruncatedFamily, TruncatedMap, paper
from hovering.paper import QW1, QW2, V1, V2, H

CODE = {
    "1": int(hovering.Region.UPPER),
    "R": int(hovering.Region.RIGHT),
    "0": int(hovering.Region.ABOVE),
    "u": int(hovering.Region.BESIDE),
}


def compare(eps, K, n_phi=24, n_modes=6):
    """Largest |d phi|, |d K| between full and truncated maps on the circle K (points whose regions agree)."""
    p = hovering.onset_parameters(StepSystem(V1=V1, V2=V2, qw1=QW1, qw2=QW2), H)
    sec = paper.section(eps)
    phi_s = np.linspace(-3.1, 3.1, 64)
    f = hovering.forcing_function(sec, phi_s)
    A = np.stack([np.sin((k + 1) * phi_s) for k in range(n_modes)], 1)
    b = np.linalg.lstsq(A, f, rcond=None)[0]
    m = TruncatedMap(eps=eps, Omega0=p.Omega0, theta_w=p.theta_w, tau0=p.tau0, tau1=p.tau1, lam=p.lam)
    grid = np.concatenate([-(np.linspace(0.3, 0.0, 31) ** 2) * 10 / 9, np.linspace(0.01, 0.3, 10)])
    fam = TruncatedFamily.from_map(m, grid, forcing=tuple(b))
    ph = np.linspace(-3.0, 3.0, n_phi)
    th, I = hovering.from_normal(sec, ph, np.full_like(ph, K))
    out = sec.return_map(th, I, rtol=1e-12, atol=1e-14)
    pb, Kb = hovering.to_normal(sec, out.theta, out.I)
    pt, Kt = fam.step(ph, np.full_like(ph, K))
    reg = fam.region(ph, np.full_like(ph, K))
    same = np.array([CODE.get(s, -2) == r for s, r in zip(out.itinerary, reg)]) & (out.status == 0)
    return dict(
        same=int(same.sum()),
        n=n_phi,
        dphi=float(np.abs(hovering.wrap(pb - pt))[same].max()),
        dK=float(np.abs(Kb - Kt)[same].max()),
        b=b,
    )


def main():
    print(
        f"{'eps':>6s} {'K':>6s} {'regions agree':>14s} {'max|dphi|':>10s} {'max|dK|':>10s} {'dK/(eps|K|)':>12s} {'b1':>7s} {'b2':>7s}"
    )
    for eps in (0.005, 0.01, 0.02):
        for K in (-0.03, -0.01, 0.01, 0.03):
            r = compare(eps, K)
            print(
                f"{eps:6.3f} {K:+6.2f} {r['same']:>8d}/{r['n']:<5d} {r['dphi']:10.2e} {r['dK']:10.2e} "
                f"{r['dK'] / (eps * abs(K)):12.2f} {r['b'][0]:7.3f} {r['b'][1]:7.4f}"
            )


if __name__ == "__main__":
    main()
