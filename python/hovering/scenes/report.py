"""Text of scene results: the JSON-able summary of the numbers shown, and its printed form.

Pure functions of a result (the iminuit ``_repr_text`` role): nothing here computes.
"""

from __future__ import annotations

import numpy as np

from .._enums import Region, Status
from .results import (FlowHoveringResult, FlowPortraitResult, HoveringAreaResult, OrbitPanelResult, OrbitSceneResult,
                      OrbitSet, SigmaStructureResult, TangentToriResult, jsonable)

__all__ = ["summarize", "format_summary"]


def _orbits(o: OrbitSet) -> list:
    out = []
    for i, lab in enumerate(o.labels):
        K = o.K[i]
        d = dict(label=lab, kind=o.kinds[i], phi0=float(o.phi[i, 0]), K0=float(K[0]), K_min=float(np.nanmin(K)),
                 K_max=float(np.nanmax(K)), status=Status(int(o.status[i])).name, steps=int(o.steps_done[i]))
        if o.rho is not None:
            d["rho"] = float(o.rho[i])
        if o.region is not None:
            reg = o.region[i]
            d["impacts"] = int(np.count_nonzero((reg == int(Region.UPPER)) | (reg == int(Region.RIGHT))
                                                | (reg == int(Region.MULTI))))
            d["hovering"] = bool(d["impacts"] == 0 and d["K_min"] < 0 and o.status[i] == int(Status.OK))
        out.append(d)
    return out


def _region_counts(region) -> dict:
    if region is None:
        return {}
    return {Region(r).label: int(np.count_nonzero(region == int(r))) for r in Region if r != Region.NONE}


def summarize(result) -> dict:
    """The numbers a scene result shows, as a JSON-able dict.

    Parameters
    ----------
    result : SceneResult
        Any scene result.

    Returns
    -------
    dict
        ``scene``, ``kind``, ``title``, ``quick``, ``n_steps`` (when it has one), ``runtime_s`` and
        per kind: ``panels`` (orbit scenes), ``series`` (hovering_area), ``flow`` / ``model``
        (flow_portrait), ``points`` (flow_hovering_area), ``tori`` (tangent_tori), ``regions``
        (sigma_structure).
    """
    sc, meta = result.scene, result.meta
    s = dict(scene=sc.name, kind=sc.kind, title=sc.title, quick=bool(meta.get("quick")),
             runtime_s=float(meta.get("timings", {}).get("total", float("nan"))))
    for k in ("n_steps", "samples", "points_reused", "checkpoint", "grid", "accuracy"):
        if k in meta:
            s[k] = meta[k]
    if isinstance(result, OrbitSceneResult):
        panels = []
        for p in result.panels:
            if isinstance(p, OrbitPanelResult):
                info = dict(id=p.id, params=p.params, K_crit=p.K_crit, rho_crit=p.rho_crit, band_floor=p.band_floor,
                            orbits=_orbits(p.orbits), n_escaped=int(np.count_nonzero(p.orbits.status == int(Status.ESCAPED))),
                            xlim=list(p.xlim), ylim=list(p.ylim), n_orbits_drawn=p.orbits.n_orbits)
                if p.critical is not None:
                    info["critical"] = p.critical
            else:
                info = dict(id=p.id, zoom_of=p.of, window=p.window)
            panels.append(info)
        s["panels"] = panels
    elif isinstance(result, HoveringAreaResult):
        s["series"] = [dict(label=r.label, golden_c=r.golden_c, points=[
            dict(eps=float(e), area=float(a), error=float(er), theory=float(t), floor_touched=bool(f), K_low=float(kl),
                 Omega0=float(O), theta_w=float(tw))
            for e, a, er, t, f, kl, O, tw in zip(r.eps, r.area, r.error, r.theory, r.floor_touched, r.K_low, r.Omega0,
                                                 r.theta_w)]) for r in result.series]
    elif isinstance(result, FlowPortraitResult):
        s.update(onset=result.onset, forcing=result.forcing[:3], model_name=result.model_name, work=result.work)
        for name, o in (("flow", result.flow), ("model", result.model)):
            s[name] = dict(orbits=_orbits(o), regions=_region_counts(o.region),
                           statuses={Status(int(v)).name: int(np.count_nonzero(o.status == v))
                                     for v in np.unique(o.status)})
    elif isinstance(result, FlowHoveringResult):
        pts = []
        for i, e in enumerate(result.eps):
            d = dict(eps=float(e), flow=float(result.flow_area[i]), flow_error=float(result.flow_error[i]),
                     flow_both_sides=float(result.flow_both_sides[i]), theory=float(result.theory[i]),
                     K_low=float(result.K_low[i]), b1=float(result.b1[i]), seconds=float(result.seconds[i]),
                     unresolved=int(result.unresolved[i]))
            d["models"] = {m: {k: float(v[i]) for k, v in cols.items()} for m, cols in result.models.items()}
            pts.append(d)
        s["points"] = pts
    elif isinstance(result, TangentToriResult):
        s["tori"] = [dict(name=t.name, h1=t.h1, h2=t.h2, trajectory_points=int(t.trajectory.shape[0]),
                          q1_min=float(np.nanmin(t.trajectory[:, 1])) if t.trajectory.size else None,
                          q2_min=float(np.nanmin(t.trajectory[:, 3])) if t.trajectory.size else None)
                     for t in result.tori]
        s.update(qw1=result.qw1, qw2=result.qw2, status=meta.get("status", {}), work=meta.get("work", {}))
    elif isinstance(result, SigmaStructureResult):
        s["regions"] = _region_counts(result.region)
        s["points"] = int(result.phi.size)
    return jsonable(s)


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
        it = ", ".join(f"{k} {f(v, 'g')}" if isinstance(v, float) or v is None else f"{k} {v}"
                       for k, v in acc["integrator"].items() if k in ("stepper", "rtol", "atol"))
        lines.append(f"  integrator: {it}; reversal error after {acc['reversal_returns']} returns "
                     f"({acc['reversal_orbits']} orbits): {f(acc['reversal_error'], '.2g')} (grows as m^2)")
    for p in summary.get("panels", []):
        if "zoom_of" in p:
            w = p.get("window")
            lines.append(f"  panel ({p['id']}): zoom of ({p['zoom_of']}), window phi {_fmt_pair(w['xlim'])}, "
                         f"K {_fmt_pair(w['ylim'])} [{w['rule']}]")
            continue
        par = p["params"]
        extra = (f", golden c = {f(par['golden_c'], 'g')} at eps = {f(par['golden_eps'], 'g')}"
                 if "golden_c" in par else "")
        lines.append(f"  panel ({p['id']}): eps = {f(par['eps'], 'g')}, Omega0 = {f(par['Omega0'], '.5f')}, "
                     f"theta_w = {f(par['theta_w'], '.5f')}{extra}; predicted K~_c = {f(p['K_crit'], '.4f')}, "
                     f"rho_c = {f(p['rho_crit'], '.4f')}")
        if p["orbits"] and p["orbits"][0]["kind"] == "fan":
            lines.append(f"    {len(p['orbits'])} orbits from K0 = {f(p['orbits'][0]['K0'], '.4g')} to "
                         f"{f(p['orbits'][-1]['K0'], '.4g')}, {p['n_escaped']} escaped the band")
        else:
            for o in p["orbits"]:
                hov = ("hovering" if o.get("hovering") else
                       ("no impact" if o.get("impacts") == 0 else f"{o.get('impacts')} impacts"))
                lines.append(f"    {o['label']:>10}: K0 = {f(o['K0'], '+.5f')}, K_min = {f(o['K_min'], '+.5f')}, "
                             f"rho = {f(o.get('rho'), '.4f')}, {hov}, {o['status']}")
        c = p.get("critical")
        if c is not None:
            if c["found"]:
                lines.append(f"    critical curve: K0 = {f(c['K0'], '+.5f')}, K_min = {f(c['K_min'], '+.5f')}, "
                             f"rho = {f(c['rotation_mean'], '.4f')} (Birkhoff {f(c['rotation'], '.6f')}); predicted "
                             f"K~_c = {f(c['K_pred'], '+.4f')}, rho_c = {f(c['rotation_pred'], '.4f')}")
            else:
                lines.append(f"    critical curve: not found ({c['reason']})")
    for s in summary.get("series", []):
        lines.append(f"  {s['label']}:")
        for r in s["points"]:
            flag = "  (box floor touched)" if r["floor_touched"] else ""
            lines.append(f"    eps = {f(r['eps'], '+.3f')}: |HOV| = {f(r['area'], '.4f')} +- {f(r['error'], '.4f')}, "
                         f"theory {f(r['theory'], '.4f')}{flag}")
    if "flow" in summary and "model" in summary:
        o = summary["onset"]
        lines.append(f"  onset: Omega0 = {f(o['Omega0'], '.5f')}, theta_w = {f(o['theta_w'], '.5f')}, "
                     f"tau0 = {f(o['tau0'], '.4f')}, tau1 = {f(o['tau1'], '.4f')}, lam = {f(o['lam'], '.4f')}; "
                     f"model: {summary['model_name']} forcing")
        for name in ("flow", "model"):
            d = summary[name]
            hov = sum(1 for x in d["orbits"] if x.get("hovering"))
            lines.append(f"  {name:>5}: {len(d['orbits'])} orbits, {hov} hovering, regions {d['regions']}, "
                         f"statuses {d['statuses']}")
    for r in summary.get("points", []) if isinstance(summary.get("points"), list) else []:
        mod = ", ".join(f"{m} {f(v['area'], '.4f')} +- {f(v['error'], '.4f')} " + (
            f"(agree {f(100 * v['agree'], '.1f')}%)" if v.get("agree") is not None else
            f"(own box from K = {f(v.get('K_low'), '.4f')}: its band ends there)") for m, v in r["models"].items())
        lines.append(f"  eps = {f(r['eps'], '+.3f')}: flow |HOV| = {f(r['flow'], '.4f')} "
                     f"+- {f(r['flow_error'], '.4f')} "
                     f"[both sides {f(r['flow_both_sides'], '.4f')}], {mod}, eq:hovsetsize {f(r['theory'], '.4f')} "
                     f"({f(r['seconds'], '.1f')} s)")
    for t in summary.get("tori", []):
        lines.append(f"  {t['name']} torus: h1 = {f(t['h1'], '.5f')}, h2 = {f(t['h2'], '.5f')}, "
                     f"{t['trajectory_points']} trajectory samples, min q1 = {f(t['q1_min'], '.6f')} "
                     f"(qw1 = {f(summary['qw1'], 'g')}), min q2 = {f(t['q2_min'], '.6f')} "
                     f"(qw2 = {f(summary['qw2'], 'g')})")
    if "regions" in summary and "flow" not in summary:
        lines.append(f"  {summary['points']} points of the band, regions {summary['regions']}")
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
