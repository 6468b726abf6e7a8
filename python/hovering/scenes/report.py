"""Text of scene results: the JSON-able summary of the numbers shown, and its printed form.

Pure functions of a result (the iminuit ``_repr_text`` role): nothing here computes.
"""

from __future__ import annotations

import numpy as np

from .results import summarize

__all__ = ["summarize", "format_summary"]  # summarize: re-exported from .results, its home


def format_summary(summary: dict) -> str:
    """Human-readable text of a scene summary (what the CLI prints).

    Every number goes through one formatter: a value that is not a finite number (NaN, stored as
    None in the JSON-able summary, e.g. the theory at Omega0 = 2 pi or a checkpoint row without an
    area) prints as ``nan`` (``inf``), never an error.

    Parameters
    ----------
    summary : dict
        From :func:`summarize` (plus ``output``, ``npz``, ``json`` and ``files`` when the result
        was written).

    Returns
    -------
    str
    """
    f = _f
    head = f"scene {summary['scene']} ({summary['kind']})"
    if "n_steps" in summary:
        head += f", {summary['n_steps']} iterates"
    lines = [head + (" [quick]" if summary["quick"] else "")]
    acc = summary.get("accuracy")
    if acc:
        it = ", ".join(
            f"{k} {f(v, 'g')}" if isinstance(v, float) or v is None else f"{k} {v}"
            for k, v in acc["integrator"].items()
            if k in ("stepper", "rtol", "atol")
        )
        lines.append(
            f"  integrator: {it}; reversal error after {acc['reversal_returns']} returns "
            f"({acc['reversal_orbits']} orbits): {f(acc['reversal_error'], '.2g')} (grows as m^2)"
        )
    for p in summary.get("panels", []):
        if "zoom_of" in p:
            w = p.get("window")
            lines.append(
                f"  panel ({p['id']}): zoom of ({p['zoom_of']}), window phi {_fmt_pair(w['xlim'])}, "
                f"K {_fmt_pair(w['ylim'])} [{w['rule']}]"
            )
            continue
        par = p["params"]
        extra = (
            f", golden c = {f(par['golden_c'], 'g')} at eps = {f(par['golden_eps'], 'g')}" if "golden_c" in par else ""
        )
        lines.append(
            f"  panel ({p['id']}): eps = {f(par['eps'], 'g')}, Omega0 = {f(par['Omega0'], '.5f')}, "
            f"theta_w = {f(par['theta_w'], '.5f')}{extra}; predicted K~_c = {f(p['K_crit'], '.4f')}, "
            f"rho_c = {f(p['rho_crit'], '.4f')}"
        )
        if p["orbits"] and p["orbits"][0]["kind"] == "fan":
            lines.append(
                f"    {len(p['orbits'])} orbits from K0 = {f(p['orbits'][0]['K0'], '.4g')} to "
                f"{f(p['orbits'][-1]['K0'], '.4g')}, {p['n_escaped']} escaped the band"
            )
        else:
            for o in p["orbits"]:
                hov = (
                    "hovering"
                    if o.get("hovering")
                    else ("no impact" if o.get("impacts") == 0 else f"{o.get('impacts')} impacts")
                )
                lines.append(
                    f"    {o['label']:>10}: K0 = {f(o['K0'], '+.5f')}, K_min = {f(o['K_min'], '+.5f')}, "
                    f"rho = {f(o.get('rho'), '.4f')}, {hov}, {o['status']}"
                )
        c = p.get("critical")
        if c is not None:
            if c["found"]:
                lines.append(
                    f"    critical curve: K0 = {f(c['K0'], '+.5f')}, K_min = {f(c['K_min'], '+.5f')}, "
                    f"rho = {f(c['rotation_mean'], '.4f')} (Birkhoff {f(c['rotation'], '.6f')}); predicted "
                    f"K~_c = {f(c['K_pred'], '+.4f')}, rho_c = {f(c['rotation_pred'], '.4f')}"
                )
            else:
                lines.append(f"    critical curve: not found ({c['reason']})")
    for s in summary.get("series", []):
        lines.append(f"  {s['label']}:")
        for r in s["points"]:
            flag = "  (box floor touched)" if r["floor_touched"] else ""
            lines.append(
                f"    eps = {f(r['eps'], '+.3f')}: |HOV| = {f(r['area'], '.4f')} +- {f(r['error'], '.4f')}, "
                f"theory {f(r['theory'], '.4f')}{flag}"
            )
    if "flow" in summary and "model" in summary and summary.get("kind") == "flow_portrait":
        o = summary["onset"]
        lines.append(
            f"  onset: Omega0 = {f(o['Omega0'], '.5f')}, theta_w = {f(o['theta_w'], '.5f')}, "
            f"tau0 = {f(o['tau0'], '.4f')}, tau1 = {f(o['tau1'], '.4f')}, lam = {f(o['lam'], '.4f')}; "
            f"model: {summary['model_name']} forcing"
        )
        for name in ("flow", "model"):
            d = summary[name]
            hov = sum(1 for x in d["orbits"] if x.get("hovering"))
            lines.append(
                f"  {name:>5}: {len(d['orbits'])} orbits, {hov} hovering, regions {d['regions']}, "
                f"statuses {d['statuses']}"
            )
    for r in summary.get("points", []) if isinstance(summary.get("points"), list) else []:
        mod = ", ".join(
            f"{m} {f(v['area'], '.4f')} +- {f(v['error'], '.4f')} "
            + (
                f"(agree {f(100 * v['agree'], '.1f')}%)"
                if v.get("agree") is not None
                else f"(own box from K = {f(v.get('K_low'), '.4f')}: its band ends there)"
            )
            for m, v in r["models"].items()
        )
        lines.append(
            f"  eps = {f(r['eps'], '+.3f')}: flow |HOV| = {f(r['flow'], '.4f')} "
            f"+- {f(r['flow_error'], '.4f')} "
            f"[both sides {f(r['flow_both_sides'], '.4f')}], {mod}, eq:hovsetsize {f(r['theory'], '.4f')} "
            f"({f(r['seconds'], '.1f')} s)"
        )
    for t in summary.get("tori", []):
        lines.append(
            f"  {t['name']} torus: h1 = {f(t['h1'], '.5f')}, h2 = {f(t['h2'], '.5f')}, "
            f"{t['trajectory_points']} trajectory samples, min q1 = {f(t['q1_min'], '.6f')} "
            f"(qw1 = {f(summary['qw1'], 'g')}), min q2 = {f(t['q2_min'], '.6f')} "
            f"(qw2 = {f(summary['qw2'], 'g')})"
        )
    kind = summary.get("kind")
    if "regions" in summary and "flow" not in summary and kind == "sigma_structure":
        lines.append(f"  {summary['points']} points of the band, regions {summary['regions']}")
    if kind == "corner_directions":
        lines.append(
            f"  corner {summary['corner']}, h_eps^w = {f(summary['step_energy'], '.6f')}, "
            f"p1w_max = {f(summary['p1w_max'], '.6f')}"
        )
        for d, c in summary["curves"].items():
            lines.append(
                f"  sigma_{d}: {c['reached']} of {c['points']} points of Sigma_h reach the corner "
                f"(largest miss {f(c['max_error'], '.2g')})"
            )
        for a in summary["arrivals"]:
            lines.append(
                f"    p_{a['direction']}, p1w = {f(a['p1w'], '.4f')}: from (phi, K) = ({f(a['phi'], '+.4f')}, "
                f"{f(a['K'], '+.5f')}), {a['status']} after t = {f(a['flight_time'], '.4f')}, "
                f"{f(a['error'], '.2g')} from the corner, p = ({f(a['momentum'][0], '+.4f')}, "
                f"{f(a['momentum'][1], '+.4f')})"
            )
    if kind == "wall_tangency":
        for p in summary["tangency_points"]:
            lines.append(
                f"  point {p['number']}: theta = {f(p['theta'], '+.4f')}, q2 = {f(p['q2'], '+.4f')}, "
                f"p2 = {f(p['p2'], '+.4f')}: step system {p['status']} {p['itinerary']!r}"
            )
        lines.append(f"  interior regions {summary['regions']}")
    if kind == "impact_zone":
        lines.append(f"  the model ({summary['model_name']} forcing) acts with eps b1, b1 = {f(summary['b1'], '.4f')}")
        for name in ("flow", "model"):
            d = summary[name]
            lines.append(
                f"  {name:>5}: {d['starts']} starts x {d['n_steps']} returns: classes {d['classes']}, "
                f"{len(d['barriers'])} barrier(s) at s = {', '.join(f(b, '.3f') for b in d['barriers']) or '-'}; "
                f"{d['spanning']} orbit(s) span s 0.1..0.9"
            )
            for direction in ("up", "down"):
                t = d[direction]
                rate = t["escape_rate"]
                lines.append(
                    f"         {direction}: {t['crossed']}/{t['orbits']} crossed s {f(t['start_s'], 'g')} -> "
                    f"{f(t['target_s'], 'g')} in {t['n_steps']} returns, s reached {f(t['s_reached'], '.3f')}"
                    + (f", rate {f(rate[0], '.2g')} +- {f(rate[1], '.1g')}" if rate else "")
                )
    if kind == "wall_section":
        b, a = summary["boundaries"], summary["arcs"]
        lines.append(
            f"  circle rho_w = {f(summary['rho_w'], '.5f')} (rho_max {f(summary['rho_max'], '.5f')}): "
            f"theta_R0 = {f(b['R0'], '+.6f')}, theta_01 = {f(b['01'], '+.6f')}, theta_1R = {f(b['1R'], '+.6f')} "
            f"(+- {f(summary['resolution'], '.1g')}); |J_R| = {f(a['R'], '.4f')}, |J_0| = {f(a['0'], '.4f')}, "
            f"|J_1| = {f(a['1'], '.4f')}"
        )
        lines.append(
            f"  corner curves measured on {summary['curve_points']} circles; segments "
            + ", ".join(f"{g['kind']}: {g['status']} {g['itinerary']!r}" for g in summary["segments"])
        )
    if "output" in summary:
        files = summary.get("files") or [summary["output"], summary["npz"]]
        lines.append(f"wrote {', '.join(str(x) for x in files)} in {f(summary['runtime_s'], '.2f')} s")
    return "\n".join(lines)


def _f(x, fmt: str) -> str:
    """``x`` formatted with ``fmt``; ``nan`` for None (how the JSON-able summary holds a NaN)."""
    if x is None:
        return "nan"
    if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
        return str(x)
    return format(float(x), fmt)


def _fmt_pair(p) -> str:
    return f"[{_f(p[0], '.3f')}, {_f(p[1], '.3f')}]"
