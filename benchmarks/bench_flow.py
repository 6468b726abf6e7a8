"""Return maps of the wall system: ours (GSL rk8pd + event search) vs scipy's solve_ivp (DOP853 +
events), time per return at matched achieved accuracy, and missed near-grazing impacts.

System: V1 = Harmonic(1), V2 = Tan(1.4, 0.7), infinite wall q1 = -1, eps = 0, h = 1. At eps = 0 every
return has an exact answer (the angle advance (2/omega1) arccos(qw1/A1) omega2 after a reflection,
Omega0(I) without), so "achieved accuracy" is the max angle error against it, not against another
integrator. Near-grazing: 200 orbits whose action lies 1e-4 .. 1e-9 below the tangent circle, so
q1 dips that far (times |V1'|) through the wall: each must reflect exactly once.

Also heyoka.py (Taylor integrator with events) when installed. Needs scipy (pip install scipy, and
optionally heyoka); not run in CI. Run: python benchmarks/bench_flow.py
"""

from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

import hovering

V1, V2 = hovering.Harmonic(1.0), hovering.Tan(1.4, 0.7)
QW1, H = -1.0, 1.0
SYS = hovering.StepSystem(V1=V1, V2=V2, coupling=hovering.Bilinear(), eps=0.0, qw1=QW1, qw2=-0.5, geometry="wall")
SEC = hovering.Section(SYS, H)


def exact_angle(I):
    e2 = V2.energy(I)
    h1 = H - e2
    A = np.sqrt(2 * h1)
    T = 2 * np.arccos(QW1 / A) if QW1 > -A else V1.period(h1)
    return V2.frequency(e2) * T, QW1 > -A


def rhs(t, z):
    return [z[1], -V1.dV(z[0]), z[3], -V2.dV(z[2])]


def scipy_return(z0, rtol):
    """Return map with solve_ivp: wall event (terminal: reflect, restart), q1's minimum (arms the
    section) and the section event (p1 from + to -), all filtered to times after the restart."""
    def wall(t, z):
        return z[0] - QW1
    wall.terminal, wall.direction = True, -1

    def section(t, z):
        return z[1]
    section.direction = -1

    def q1_min(t, z):
        return z[1]
    q1_min.direction = 1

    z, t, impacts, armed = np.array(z0, float), 0.0, 0, False
    while impacts < 10:
        sol = solve_ivp(rhs, (t, t + 20), z, method="DOP853", rtol=rtol, atol=rtol * 1e-2, events=[wall, section, q1_min])
        evs = [(te, k, ye) for k in range(3) for te, ye in zip(sol.t_events[k], sol.y_events[k]) if te > t + 1e-9]
        for te, k, ye in sorted(evs, key=lambda e: e[0]):
            if k == 2:
                armed = True
            elif k == 1 and armed:
                return ye, impacts
            elif k == 0:
                z = ye.copy()
                z[0], z[1] = QW1, -z[1]
                t, impacts, armed = te, impacts + 1, True
                break
        else:
            z, t = sol.y[:, -1], sol.t[-1]
    raise RuntimeError("no return")


def heyoka_integrator(rtol):
    """One compiled Taylor integrator per tolerance: wall (terminal), section, q1's minimum."""
    import heyoka as hy

    q1, p1, q2, p2 = hy.make_vars("q1", "p1", "q2", "p2")
    w2, a2 = V2.omega, V2.alpha
    sys = [(q1, p1), (p1, -q1), (q2, p2), (p2, -(w2**2 / a2) * hy.tan(a2 * q2) / hy.cos(a2 * q2) ** 2)]
    ev = [hy.t_event(q1 - QW1, direction=hy.event_direction.negative),
          hy.t_event(p1, direction=hy.event_direction.negative),
          hy.t_event(p1, direction=hy.event_direction.positive)]
    return hy.taylor_adaptive(sys, [1.0, 0.0, 0.0, 0.1], t_events=ev, tol=rtol)


def heyoka_return(ta, z0):
    """Return map with heyoka.py: terminal outcome -(i+1) names the event i that stopped it."""
    ta.time = 0.0
    ta.state[:] = z0
    ta.reset_cooldowns()
    armed, impacts = False, 0
    for _ in range(50):
        oc = int(ta.propagate_until(ta.time + 20.0)[0])
        if oc == -1:
            ta.state[0], ta.state[1] = QW1, -ta.state[1]
            impacts, armed = impacts + 1, True
        elif oc == -3:
            armed = True
        elif oc == -2 and armed:
            return ta.state.copy(), impacts
        elif oc != -2:
            raise RuntimeError(f"heyoka stopped with outcome {oc}")
    raise RuntimeError("no return")


def angle_error(theta0, I, theta1):
    d, _ = exact_angle(I)
    return abs(hovering.wrap(theta1 - theta0 - d))


def main():
    I_tan = V2.action(H - V1.V(QW1))
    rng = np.random.default_rng(0)
    n = 200
    th = rng.uniform(-np.pi, np.pi, n)
    I = I_tan * rng.uniform(0.3, 1.3, n)
    print(f"wall system, eps = 0, {n} returns per setting (both sides of the tangent circle I_tan = {I_tan:.4f})")
    print(f"{'method':28s} {'rtol':>7s} {'max angle error':>16s} {'us/return':>10s}")
    ours = {}
    for rtol in (1e-6, 1e-9, 1e-12):
        t0 = time.perf_counter()
        out = SEC.return_map(th, I, rtol=rtol, atol=rtol * 1e-2, n_threads=1)
        dt = (time.perf_counter() - t0) / n
        err = max(angle_error(a, b, c) for a, b, c in zip(th, I, out.theta))
        ours[rtol] = (err, dt)
        print(f"{'hovering rk8pd, 1 thread':28s} {rtol:7.0e} {err:16.2e} {1e6 * dt:10.1f}")
    z0 = SEC.point(th, I)
    sc = {}
    for rtol in (1e-6, 1e-9, 1e-12):
        t0 = time.perf_counter()
        thetas = []
        for z in z0:
            ze, _ = scipy_return(z, rtol)
            thetas.append(SEC.coordinates(ze)[0, 0])
        dt = (time.perf_counter() - t0) / n
        err = max(angle_error(a, b, c) for a, b, c in zip(th, I, thetas))
        sc[rtol] = (err, dt)
        print(f"{'scipy solve_ivp DOP853':28s} {rtol:7.0e} {err:16.2e} {1e6 * dt:10.1f}")
    hk = {}
    try:
        import heyoka  # noqa: F401

        for rtol in (1e-6, 1e-9, 1e-12):
            t0 = time.perf_counter()
            ta = heyoka_integrator(rtol)
            compile_s = time.perf_counter() - t0
            t0 = time.perf_counter()
            thetas = [SEC.coordinates(heyoka_return(ta, z)[0])[0, 0] for z in z0]
            dt = (time.perf_counter() - t0) / n
            err = max(angle_error(a, b, c) for a, b, c in zip(th, I, thetas))
            hk[rtol] = (err, dt, ta)
            print(f"{'heyoka.py Taylor':28s} {rtol:7.0e} {err:16.2e} {1e6 * dt:10.1f}   (+{compile_s:.2f} s to compile)")
    except ImportError:
        print("heyoka.py not installed: skipped (pip install heyoka)")
    print("speed-up at the same rtol (scipy time / ours):",
          ", ".join(f"{r:.0e}: {sc[r][1] / ours[r][1]:.0f}x" for r in ours))

    # Near-grazing impacts: every one of these orbits must reflect once.
    depths = np.logspace(-4, -9, 6)
    print(f"\nmissed impacts out of 40 per depth (action below I_tan by depth; q1 dips ~ depth x omega2):")
    if hk:
        print("speed-up at the same rtol (heyoka time / ours):", ", ".join(f"{r:.0e}: {hk[r][1] / ours[r][1]:.1f}x" for r in ours))
    print(f"{'depth':>8s} {'hovering 1e-6':>14s} {'hovering 1e-12':>15s} {'scipy 1e-6':>11s} {'scipy 1e-12':>12s}"
          f"{' heyoka 1e-6 heyoka 1e-12' if hk else ''}")
    for d in depths:
        tt = np.linspace(-3.1, 3.1, 40)
        row = []
        for rtol in (1e-6, 1e-12):
            out = SEC.return_map(tt, np.full(40, I_tan - d), rtol=rtol, atol=rtol * 1e-2)
            row.append(sum(s != "R" for s in out.itinerary))
        zz = SEC.point(tt, np.full(40, I_tan - d))
        for rtol in (1e-6, 1e-12):
            row.append(sum(scipy_return(z, rtol)[1] != 1 for z in zz))
        extra = ""
        if hk:
            extra = "".join(f" {sum(heyoka_return(hk[r][2], z)[1] != 1 for z in zz):11d}" for r in (1e-6, 1e-12))
        print(f"{d:8.0e} {row[0]:14d} {row[1]:15d} {row[2]:11d} {row[3]:12d}{extra}")


if __name__ == "__main__":
    main()
