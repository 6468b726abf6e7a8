"""The step system's flow in heyoka.py, in the forms a heyoka.py user writes (shared by the benchmarks).

One owner of the heyoka.py drivers: ``bench_taylor.py`` (work-precision, FlowMap.iterate against the
stream forms) and ``bench_per_call.py`` (one call per return; a lone orbit) both use
:class:`HeyokaFlow`. Its forms (see bench_taylor.py's docstring for the details):

loop     every event terminal without callback, one propagate_until per event, Python reflects.
1call    one propagate_until per return: wall callbacks reflect (Python), the section stops.
stream   one propagate_until for many returns, the section a non-terminal event that records.
batch    the stream form in taylor_adaptive_batch (heyoka's SIMD width).

Importing this module needs heyoka.py (ImportError otherwise: the scripts say so).
"""

from __future__ import annotations

import time

import heyoka as hy
import numpy as np

from hovering.flow.system import Bilinear, Harmonic, Polynomial, Tan

__all__ = ["HeyokaFlow", "collect_crossings", "NEG", "POS", "TIME_LIMIT"]

NEG, POS = hy.event_direction.negative, hy.event_direction.positive
TIME_LIMIT = int(hy.taylor_outcome.time_limit)


def _force(V, q):
    """-dV/dq as a heyoka expression (Tan: one tan, (w^2/a) t (1 + t^2))."""
    if isinstance(V, Tan):
        t = hy.tan(V.alpha * q)
        return -(V.omega**2 / V.alpha) * t * (1.0 + t * t)
    if isinstance(V, Harmonic):
        return -(V.omega**2) * q
    raise ValueError(f"heyoka forms need Harmonic or Tan potentials, got {V!r}")


def _coupling_forces(coupling, q1, q2):
    """(-dVc/dq1, -dVc/dq2) of a Polynomial coupling sum c q1^i q2^j as heyoka expressions, term by
    term (c i q1^(i-1) q2^j; integer powers as heyoka's pow, whose recurrences heyoka picks itself)."""
    if isinstance(coupling, Polynomial):

        def mono(i, j):
            out = 1.0
            for v, e in ((q1, i), (q2, j)):
                if e == 1:
                    out = out * v
                elif e > 1:
                    out = out * v**e
            return out

        g1 = sum((c * i * mono(i - 1, j) for (i, j), c in coupling.coefficients.items() if i > 0), 0.0 * q1)
        g2 = sum((c * j * mono(i, j - 1) for (i, j), c in coupling.coefficients.items() if j > 0), 0.0 * q2)
        return -g1, -g2
    raise ValueError(f"a Polynomial coupling expected, got {coupling!r}")


class HeyokaFlow:
    """heyoka.py integrators of one system's flow in the four forms, compiled once per (form, tol).

    The wall rule is owned here: a crossing of q1 = qw1 downward reflects p1 when there is only
    the wall, or when q2 < qw2 (beside the step); a crossing of q2 = qw2 downward reflects p2 when
    q1 < qw1 (on top of the step). The section is p1 = 0 crossed downward (q1's maximum); every
    such crossing at t > 0 is a return (a reflection at the right wall turns p1 from - to +).
    """

    def __init__(self, sec):
        s = sec.sys
        if s.geometry not in ("wall", "step"):
            raise ValueError(f"walls needed, got geometry {s.geometry!r}")
        if s.eps != 0 and not isinstance(s.coupling, (Bilinear, Polynomial)):
            raise ValueError(f"only the bilinear and polynomial couplings are written out here, got {s.coupling!r}")
        self.sec, self.sys = sec, s
        self.step = s.geometry == "step"
        self.last_steps = 0  # batched(): steps taken by its real starts in its last call
        self.vars = q1, p1, q2, p2 = hy.make_vars("q1", "p1", "q2", "p2")
        f1, f2 = _force(s.V1, q1), _force(s.V2, q2)
        if s.eps != 0 and isinstance(s.coupling, Bilinear):
            f1, f2 = f1 - s.eps * q2, f2 - s.eps * q1
        elif s.eps != 0:
            c1, c2 = _coupling_forces(s.coupling, q1, q2)
            f1, f2 = f1 + s.eps * c1, f2 + s.eps * c2
        self.eqs = [(q1, p1), (p1, f1), (q2, p2), (p2, f2)]
        self.impacts = [0]  # reflections counted by the callbacks (part 3)
        self._cache = {}
        self.batch = int(hy.recommended_simd_size())

    # -- the wall rule, as scalar and batch callbacks (Python: called at every wall crossing)
    def _scalar_walls(self):
        qw1, qw2, wall_only, count = self.sys.qw1, self.sys.qw2, not self.step, self.impacts

        def right(ta, d_sgn):
            z = ta.state
            if wall_only or z[2] < qw2:
                z[0], z[1] = qw1, -z[1]
                count[0] += 1
            return True

        def upper(ta, d_sgn):
            z = ta.state
            if z[0] < qw1:
                z[2], z[3] = qw2, -z[3]
                count[0] += 1
            return True

        q1, _, q2, _ = self.vars
        ev = [hy.t_event(q1 - qw1, callback=right, direction=NEG)]
        if self.step:
            ev.append(hy.t_event(q2 - qw2, callback=upper, direction=NEG))
        return ev

    def _batch_walls(self):
        qw1, qw2, wall_only = self.sys.qw1, self.sys.qw2, not self.step

        def right(ta, d_sgn, b):
            z = ta.state
            if wall_only or z[2, b] < qw2:
                z[0, b], z[1, b] = qw1, -z[1, b]
            return True

        def upper(ta, d_sgn, b):
            z = ta.state
            if z[0, b] < qw1:
                z[2, b], z[3, b] = qw2, -z[3, b]
            return True

        q1, _, q2, _ = self.vars
        ev = [hy.t_event_batch(q1 - qw1, callback=right, direction=NEG)]
        if self.step:
            ev.append(hy.t_event_batch(q2 - qw2, callback=upper, direction=NEG))
        return ev

    def integrator(self, form: str, tol: float):
        """The compiled integrator of a form at tol (and its bookkeeping), built once (untimed)."""
        key = (form, tol)
        if key in self._cache:
            return self._cache[key]
        q1, p1, q2, _ = self.vars
        z0 = [self.sys.qw1 * 0.5, 0.0, 0.0, 0.1]
        if form == "loop":
            ev = [hy.t_event(q1 - self.sys.qw1, direction=NEG), hy.t_event(p1, direction=NEG)]
            if self.step:
                ev.append(hy.t_event(q2 - self.sys.qw2, direction=NEG))
            out = hy.taylor_adaptive(self.eqs, z0, t_events=ev, tol=tol)
        elif form == "1call":
            ev = self._scalar_walls() + [hy.t_event(p1, direction=NEG)]
            out = (hy.taylor_adaptive(self.eqs, z0, t_events=ev, tol=tol), -len(ev))
        elif form == "stream":
            rec = []

            def crossing(ta, t, d_sgn):
                if t > 0:
                    ta.update_d_output(t)
                    rec.append(ta.d_output.copy())

            ta = hy.taylor_adaptive(
                self.eqs,
                z0,
                t_events=self._scalar_walls(),
                nt_events=[hy.nt_event(p1, crossing, direction=NEG)],
                tol=tol,
            )
            out = (ta, rec)
        elif form == "batch":
            B = self.batch
            recs = [[] for _ in range(B)]

            def crossing_b(ta, t, d_sgn, b):
                if t > 0:
                    times = ta.time.copy()
                    times[b] = t
                    ta.update_d_output(times)
                    recs[b].append(ta.d_output[:, b].copy())

            ta = hy.taylor_adaptive_batch(
                self.eqs,
                np.tile(np.array(z0)[:, None], (1, B)),
                t_events=self._batch_walls(),
                nt_events=[hy.nt_event_batch(p1, crossing_b, direction=NEG)],
                tol=tol,
            )
            out = (ta, recs)
        else:
            raise ValueError(form)
        self._cache[key] = out
        return out

    # -- the forms: each returns (first-return states (n, 4) with NaN rows where none was found,
    #    returns done, seconds of the timed part)
    def loop(self, z0s, tol):
        ta = self.integrator("loop", tol)
        qw1, qw2, step = self.sys.qw1, self.sys.qw2, self.step
        out = np.full((len(z0s), 4), np.nan)
        t0 = time.perf_counter()
        for i, z0 in enumerate(z0s):
            ta.time = 0.0
            ta.state[:] = z0
            ta.reset_cooldowns()
            for _ in range(200):
                oc = int(ta.propagate_until(ta.time + 50.0)[0])
                z = ta.state
                if oc == -2:
                    if ta.time > 0:
                        out[i] = z
                        break
                elif oc == -1:
                    if not step or z[2] < qw2:
                        z[0], z[1] = qw1, -z[1]
                elif oc == -3:
                    if z[0] < qw1:
                        z[2], z[3] = qw2, -z[3]
                elif oc != TIME_LIMIT:
                    break  # an error outcome: no return
        return out, len(z0s), time.perf_counter() - t0

    def onecall(self, z0s, tol):
        ta, sec_oc = self.integrator("1call", tol)
        out = np.full((len(z0s), 4), np.nan)
        impacts = np.zeros(len(z0s), int)
        t0 = time.perf_counter()
        for i, z0 in enumerate(z0s):
            ta.time = 0.0
            ta.state[:] = z0
            ta.reset_cooldowns()
            self.impacts[0] = 0
            for _ in range(3):  # the first call stops on the start's own crossing at t = 0
                oc = int(ta.propagate_until(ta.time + 200.0)[0])
                if oc != sec_oc or ta.time > 0:
                    break
            if oc == sec_oc and ta.time > 0:
                out[i] = ta.state
            impacts[i] = self.impacts[0]
        return out, len(z0s), time.perf_counter() - t0, impacts

    def stream(self, z0s, tol, m_returns):
        ta, rec = self.integrator("stream", tol)
        out = np.full((len(z0s), 4), np.nan)
        T = 2 * np.pi * m_returns  # ~m_returns q1 periods (fewer when impacts shorten them)
        total = 0
        t0 = time.perf_counter()
        for i, z0 in enumerate(z0s):
            ta.time = 0.0
            ta.state[:] = z0
            ta.reset_cooldowns()
            rec.clear()
            ta.propagate_until(T)
            if rec:
                out[i] = rec[0]
            total += len(rec)
        return out, total, time.perf_counter() - t0

    def batched(self, z0s, tol, m_returns):
        ta, recs = self.integrator("batch", tol)
        B, n = self.batch, len(z0s)
        pad = -n % B
        Z = np.vstack([z0s, np.repeat(z0s[-1:], pad, axis=0)]) if pad else np.asarray(z0s)
        out = np.full((n, 4), np.nan)
        T = 2 * np.pi * m_returns
        total = steps = 0
        zero = np.zeros(B)
        t0 = time.perf_counter()
        for g in range(0, len(Z), B):
            ta.set_time(zero)
            ta.state[:] = Z[g : g + B].T
            ta.reset_cooldowns()
            for r in recs:
                r.clear()
            ta.propagate_until(T)
            for b in range(B):
                if g + b < n:
                    if recs[b]:
                        out[g + b] = recs[b][0]
                    total += len(recs[b])
                    steps += int(ta.propagate_res[b][3])
        self.last_steps = steps  # steps of the real starts (not the padding): per-step costs
        return out, total, time.perf_counter() - t0


def collect_crossings(hf, form, z0, K, tol=1e-10):
    """The first K section crossings of each start in a heyoka stream form at tol (NaN-padded)."""
    ta, rec = hf.integrator(form, tol)
    out = np.full((len(z0), K, 4), np.nan)
    T = 2 * np.pi * (K + 1)
    if form == "stream":
        for i, z in enumerate(z0):
            ta.time = 0.0
            ta.state[:] = z
            ta.reset_cooldowns()
            rec.clear()
            ta.propagate_until(T)
            k = min(K, len(rec))
            if k:
                out[i, :k] = np.array(rec[:k])
        return out
    B = hf.batch
    pad = -len(z0) % B
    Z = np.vstack([z0, np.repeat(z0[-1:], pad, axis=0)]) if pad else z0
    for g in range(0, len(Z), B):
        ta.set_time(np.zeros(B))
        ta.state[:] = Z[g : g + B].T
        ta.reset_cooldowns()
        for r in rec:
            r.clear()
        ta.propagate_until(T)
        for b in range(B):
            if g + b < len(z0) and rec[b]:
                k = min(K, len(rec[b]))
                out[g + b, :k] = np.array(rec[b][:k])
    return out
