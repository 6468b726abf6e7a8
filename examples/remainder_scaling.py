"""Full return map vs truncated maps: how the remainders of thm:returnmap scale with eps and K.

System: Harmonic(1), Tan(1.4, 0.7), step corner (-1, -0.5), bilinear coupling, h = 1.

1. Corner-singularity curves of the flow at eps = 0, fitted as
   phi_ab(K) = phi_ab(0) + c_s sqrt(-K) + c_K K + c_3 (-K)^{3/2}, against thm:cornersing
   (phi_ab(0), A_ab lam, tau_ab), and their eps-dependence phi^eps_ab - phi^0_ab.
2. Three truncated maps on the same (phi, K) points as the flow, for several eps:
   onset    F^trun built from the onset parameters (Omega0 + tau0 K, 2(pi - theta_w) + tau1 K, 2 lam sqrt(-K)),
   arcs0    F^trun_{eps,0}: arcs and Omega measured on the eps = 0 flow,
   arcsE    F^trun_{eps,eps}: arcs and Omega measured on the flow at that eps,
   all with the measured forcing f (eq:defoff, sine fit). Per region, max |dK| and max |dphi| are
   fitted as C eps^a |K|^b and compared with eq:gcorner / eq:gcornerphi.

Run: python examples/remainder_scaling.py   (~1 minute on 2 cores)
"""

from __future__ import annotations

import numpy as np

import hovering
from hovering import normal as fm
from hovering.paper import H, section


def corner_fit(cc, p):
    """Least-squares fit of each curve in s = sqrt(-K): phi(0), c_s, c_K, c_3, c_4 (K^2)."""
    neg = cc.K < 0
    s = np.sqrt(-cc.K[neg])
    A = np.stack([np.ones_like(s), s, -(s**2), s**3, s**4], 1)
    out = {}
    for name in ("phi_R0", "phi_01", "phi_1R"):
        y = getattr(cc, name)[neg]
        ok = np.isfinite(y)  # J_1 narrower than the phi grid at the smallest |K| is not resolved
        out[name] = np.linalg.lstsq(A[ok], np.unwrap(y[ok]), rcond=None)[0]
    return out


def scaling_fit(rows):
    """Fit log m = a log eps + b log|K| + c over rows (eps, K, m) with m > 0."""
    r = np.array([x for x in rows if x[2] > 0 and np.isfinite(x[2])])
    if len(r) < 4:
        return np.nan, np.nan
    A = np.stack([np.log(r[:, 0]), np.log(np.abs(r[:, 1])), np.ones(len(r))], 1)
    a, b, _ = np.linalg.lstsq(A, np.log(r[:, 2]), rcond=None)[0]
    return a, b


def main():
    sec0 = section(0.0)
    p = hovering.onset_parameters(sec0.sys, H)
    curve0 = fm.TangentialCurve(sec0)
    K_fit = -np.logspace(-6, np.log10(0.04), 40)
    cc0 = fm.corner_curves(sec0, K_fit, curve0)
    fit = corner_fit(cc0, p)
    theory = {
        "phi_R0": (-p.theta_w - p.Omega0 / 2, p.lam, -(p.tau0 + p.tau1) / 2),
        "phi_01": (p.theta_w - p.Omega0 / 2, -p.lam, (p.tau1 - p.tau0) / 2),
        "phi_1R": (p.theta_w - p.Omega0 / 2, p.lam, (p.tau1 - p.tau0) / 2),
    }
    print(
        f"onset parameters: Omega0 {p.Omega0:.4f} tau0 {p.tau0:.4f} tau1 {p.tau1:.4f} lam {p.lam:.4f} "
        f"theta_w {p.theta_w:.4f}"
    )
    print(
        "\n1. corner-singularity curves at eps = 0, 40 circles K in [-0.04, -1e-6] "
        "(fit phi(0) + c_s sqrt(-K) + c_K K + c_3 (-K)^1.5 + c_4 K^2):"
    )
    print(
        f"{'curve':8s} {'phi(0)':>9s} {'theory':>9s} {'c_s':>8s} {'A lam':>8s} {'c_K':>8s} {'tau_ab':>8s} "
        f"{'swapped':>8s}   (swapped: tau_R0 <-> tau_01 = tau_1R, see README)"
    )
    swapped = {"phi_R0": theory["phi_01"][2], "phi_01": theory["phi_R0"][2], "phi_1R": theory["phi_R0"][2]}
    for name, (c0, cs, cK, _, _) in fit.items():
        t0, ts, tK = theory[name]
        print(
            f"{name:8s} {hovering.wrap(c0):9.5f} {hovering.wrap(t0):9.5f} {cs:8.4f} {ts:8.4f} {cK:8.4f} {tK:8.4f} "
            f"{swapped[name]:8.4f}"
        )

    eps_list = (0.0025, 0.005, 0.01, 0.02)
    K_grid = np.concatenate([-np.linspace(0.06, 0.002, 30), [0.002, 0.01, 0.03, 0.06]])
    K_test = np.array([-0.04, -0.02, -0.01, -0.005, -0.0025, 0.002, 0.01, 0.03])
    cc0g = fm.corner_curves(sec0, K_grid, curve0)
    rows = {}
    print(
        "\n   eps-dependence of the curves (phi^eps - phi^0 at K = -1e-4 and -0.01; thm: O(eps) and O(eps sqrt(-K))):"
    )
    Kd = np.array([-1e-4, -0.01])
    ccd0 = fm.corner_curves(sec0, Kd, curve0)
    print(f"{'eps':>7s} " + " ".join(f"{n + ' K=' + format(k, '.0e'):>17s}" for n in ("R0", "01", "1R") for k in Kd))
    for eps in eps_list:
        sec = section(eps)
        curve = fm.TangentialCurve(sec)
        ccd = fm.corner_curves(sec, Kd, curve)
        d = [hovering.wrap(getattr(ccd, "phi_" + n) - getattr(ccd0, "phi_" + n)) for n in ("R0", "01", "1R")]
        print(f"{eps:7.4f} " + " ".join(f"{x / eps:17.4f}" for dd in d for x in dd) + "   (divided by eps)")
        b = fm.forcing_coefficients(sec)
        models = {
            "onset": hovering.TruncatedFamily.from_map(
                hovering.TruncatedMap(eps=eps, Omega0=p.Omega0, theta_w=p.theta_w, tau0=p.tau0, tau1=p.tau1, lam=p.lam),
                np.concatenate([-(np.linspace(0.3, 0.0, 31) ** 2) * 10 / 9, np.linspace(0.01, 0.3, 10)]),
                forcing=tuple(b),
            ),
            "arcs0": fm.truncated_from_flow(cc0g, eps, b),
            "arcsE": fm.truncated_from_flow(fm.corner_curves(sec, K_grid, curve), eps, b),
        }
        ph = np.linspace(-np.pi, np.pi, 97)[:-1] + 0.013
        P, KK = np.meshgrid(ph, K_test)
        for mname, m in models.items():
            c = fm.compare_maps(sec, curve, m, P.ravel(), KK.ravel())
            for reg in ("", "R", "1"):
                for k in K_test:
                    sel = (c.region_full == reg) & (c.K == k) & c.agree
                    if sel.any():
                        rows.setdefault((mname, reg, "K"), []).append((eps, k, np.max(np.abs(c.dK[sel]))))
                        rows.setdefault((mname, reg, "GK"), []).append((eps, k, np.max(np.abs(c.GK[sel]))))
                        rows.setdefault((mname, reg, "phi"), []).append((eps, k, np.max(np.abs(c.dphi[sel]))))
            rows.setdefault((mname, "agree"), []).append(c.agree.mean())
    print("\n2. full vs truncated maps, 96 phi x 8 circles per eps, eps in", eps_list)
    print("   fitted max|d| ~ eps^a |K|^b per region (K < 0 circles for J_R, J_1; both signs for J_0);")
    print("   GK = K_bar - K - eps f(phi_bar) at the flow's image (the theorem's G_K), K = dK, phi = dphi (= -G_phi):")
    theory = {
        ("", "GK"): "a=1 b=1 (O(eps K))",
        ("R", "GK"): "a=1 b=1/2 (O(eps sqrt(-K)))",
        ("1", "GK"): "a=1 b=1/2 (O(eps sqrt(-K)))",
        ("", "K"): "G_K + O(eps dphi)",
        ("", "phi"): "a=1 b=0 (O(eps))",
        ("R", "K"): "G_K + O(eps dphi)",
        ("R", "phi"): "a=1 b=0 (O(eps, eps sqrt(-K)))",
        ("1", "K"): "G_K + O(eps dphi)",
        ("1", "phi"): "a=1 b=0 (O(eps, eps sqrt(-K)))",
    }
    print(f"{'model':6s} {'region':6s} {'diff':4s} {'a':>6s} {'b':>6s} {'max|d|':>9s}   thm:returnmap")
    for mname in ("onset", "arcs0", "arcsE"):
        for reg in ("", "R", "1"):
            for comp in ("GK", "K", "phi"):
                r = rows.get((mname, reg, comp), [])
                a, b = scaling_fit(r)
                mx = max((x[2] for x in r), default=np.nan)
                print(
                    f"{mname:6s} {('J_' + (reg or '0')):6s} {comp:4s} {a:6.2f} {b:6.2f} {mx:9.2e}   {theory[(reg, comp)]}"
                )
        print(f"{mname:6s} regions agree on {100 * np.mean(rows[(mname, 'agree')]):.2f}% of the points")


if __name__ == "__main__":
    main()
