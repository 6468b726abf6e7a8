"""Command line of ``hovering`` (the same as ``python -m hovering``).

``hovering --version`` prints the version (without loading the compiled core or numpy); ``-v``
shows what the package logs on stderr: the stages of a run as they start and end (what, how much,
how long), each sweep point, each hovering area and transit measured (``-vv`` also its debug
records); ``-q`` only errors, and none of the lines below but the numbers.

``demo [--out PNG] [--n-steps N] [--n-orbits N]``
    The packaged demo scene: the physical flow's return map beside its truncated model.
``scene SCENE.toml [--out PNG] [--quick] [--progress | --no-progress] [--workers N [--dask] | --scheduler ADDRESS]``
    One figure from a scene file (``examples/scenes``): computes, writes the result (NPZ + JSON)
    and the PNG, prints the numbers shown. Sweep scenes run their points on N local threads, a
    Dask LocalCluster or a running Dask scheduler, each point checkpointed as it arrives.
``plan SCENE.toml [-o PLAN.toml] [--quick] [--force]``
    The resolved sweep plan of a sweep scene (docs/sweep-plan.md): every point's numbers
    explicit, for ``hovering_sweep --plan PLAN.toml``, which needs no Python at run time.
``redraw RESULT.npz [--out PNG]``
    Redraws a saved result's figure without computing.
``accuracy SCENE.toml [--quick] [--out PNG]``
    The work-precision diagram of the scene's own system (flow scenes: error of one return and of
    long orbits vs time per return, one curve per stepper; truncated-map scenes: rotation-number
    error vs time), its table on stdout and as JSON next to the PNG.
``explore SCENE.toml [--n-steps N]``
    A phase portrait where a click launches an orbit (needs an interactive matplotlib backend).

Every bad input (file, key, value, output path, format, colour) is ``error: ...`` on stderr and
exit status 2, before anything is computed.

Where outputs go: a scene's own ``output`` must lie under the scene file's folder or the working
directory (``--out`` can name any place). Existing files are replaced only if hovering wrote them
(results, sidecars, checkpoints, and figures beside them); any other file in the way is refused
before computing unless ``--force``. Every file is written atomically, and the files written are
named at the end; a failed write (a full disk) is one ``error:`` line (exit 2) and leaves the
previous files intact.
"""

from __future__ import annotations

import argparse
import logging
import sys
import time

from ._deprecated import message


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


def _error(e) -> int:
    print(f"error: {e}", file=sys.stderr)
    return 2


_quiet = False  # -q: the lines that only report (files written, times) are left out


def _say(text: str) -> None:
    if not _quiet:
        print(text)


def _logging(verbose: int, quiet: bool) -> None:
    """The package's log records (``logging.getLogger("hovering")``) on stderr at the level the
    flags ask: warnings by default, -v info, -vv debug, -q errors only."""
    level = logging.ERROR if quiet else (logging.WARNING, logging.INFO, logging.DEBUG)[min(verbose, 2)]
    log = logging.getLogger("hovering")
    log.setLevel(level)
    for h in [h for h in log.handlers if getattr(h, "_hovering_cli", False)]:
        log.removeHandler(h)  # one handler however often main() runs, on today's sys.stderr
    h = logging.StreamHandler(sys.stderr)
    h.setFormatter(logging.Formatter("%(name)s: %(levelname)s: %(message)s"))
    h._hovering_cli = True  # type: ignore[attr-defined]
    log.addHandler(h)


#: What ``demo`` runs without flags (the packaged scene's own counts are larger: a demo is quick).
_DEMO_DEFAULTS = {"n_orbits": 12, "n_steps": 1500}

#: ``demo``'s old flags and their names now (one name per concept: the scene keys, ``explore``).
_DEMO_RENAMED = {"--orbits": "--n-orbits", "--steps": "--n-steps"}


def _dest(flag: str) -> str:
    return flag[2:].replace("-", "_")


def _demo_flags(p, args) -> None:
    """``demo``'s counts: an old flag (``--steps``, ``--orbits``) still works, its value going to the
    new one with a deprecation logged (users of a command line read stderr, not Python's warning
    filters); both names at once are a usage error; neither, the default."""
    for old, new in _DEMO_RENAMED.items():
        value = getattr(args, "old_" + _dest(new))
        if value is not None:
            if getattr(args, _dest(new)) is not None:
                p.error(f"{old} is the old name of {new}: give {new} only")
            logging.getLogger(__name__).warning(message(f"hovering demo {old}", new))
            setattr(args, _dest(new), value)
        elif getattr(args, _dest(new)) is None:
            setattr(args, _dest(new), _DEMO_DEFAULTS[_dest(new)])


def _progress(args) -> bool:
    # Bars only for a person watching: on by default when stderr is a terminal, never in logs.
    return sys.stderr.isatty() if args.progress is None else args.progress


def _run(scene, out, quick: bool, progress: bool, where=None, force: bool = False) -> int:
    from .pipeline import run_scene
    from .scenes import format_summary

    try:
        summary = run_scene(scene, out=out, quick=quick, progress=progress, force=force, executor=where)
    except (OSError, ValueError, ImportError) as e:
        # a value only the computation can check (e.g. a K beyond the band's top), a file in the
        # way, a write that failed (a full disk), or a missing extra: one line, the previous files intact
        return _error(e)
    print(format_summary(summary))
    return 0


def _scene(args) -> int:
    import matplotlib

    matplotlib.use("Agg")
    from ._io.output import output_path
    from .scenes import load_scene

    try:
        # With --out the scene's own output is not used, so it is not checked.
        scene = load_scene(args.path, check_output=args.out is None)
        out = output_path("--out", args.out) if args.out is not None else None
    except (OSError, ValueError) as e:
        return _error(e)
    where = None
    if args.workers is not None or args.scheduler is not None:
        from .parallel import Executor

        try:
            where = Executor(workers=args.workers, scheduler=args.scheduler, dask=args.dask)
        except (ValueError, ImportError) as e:
            return _error(e)
    elif args.dask:
        return _error("--dask needs --workers N (a LocalCluster of N workers)")
    return _run(scene, out, args.quick, _progress(args), where, args.force)


def _demo(args) -> int:
    import tomllib

    import matplotlib

    matplotlib.use("Agg")
    from ._io.output import output_path
    from .scenes import packaged_scene, parse_scene

    path = packaged_scene("demo")
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data.update(n_steps=args.n_steps, n_orbits=args.n_orbits, dpi=args.dpi)
    data["system"]["eps"] = args.eps
    try:
        out = output_path("--out", args.out)
        scene = parse_scene(data, path)
    except ValueError as e:
        return _error(e)
    t0 = time.perf_counter()
    rc = _run(scene, out, False, _progress(args), force=args.force)
    if rc == 0:
        _say(f"demo done in {time.perf_counter() - t0:.2f} s")
    return rc


def _plan(args) -> int:
    from pathlib import Path

    from ._io.output import refuse_foreign
    from .scenes import load_scene
    from .scenes.plan import write_plan

    try:
        scene = load_scene(args.path, check_output=False)
        out = Path(args.out if args.out is not None else Path(args.path).with_suffix(".plan.toml").name)
        if out.suffix.lower() != ".toml":
            raise ValueError(f"-o {str(out)!r}: a plan is a TOML file, give a name ending in .toml")
        if not out.parent.is_dir():
            raise ValueError(f"-o {str(out)!r}: the directory {str(out.parent)!r} does not exist")
        if out.exists() and not args.force and not out.read_bytes()[:4096].startswith(b"# The resolved sweep plan"):
            refuse_foreign([out])  # a plan hovering wrote may be replaced; any other file is refused
        t0 = time.perf_counter()
        path = write_plan(scene, out, quick=args.quick)
    except (OSError, ValueError) as e:
        return _error(e)
    _say(
        f"wrote {path} ({scene.kind}, {len(scene.eps) * len(getattr(scene, 'series', [None]))} points) in "
        f"{time.perf_counter() - t0:.2f} s; run it with: hovering_sweep --plan {path}"
    )
    return 0


def _redraw(args) -> int:
    import matplotlib

    matplotlib.use("Agg")
    from ._io.output import output_path
    from .pipeline import redraw

    try:
        out = output_path("--out", args.out) if args.out is not None else None
        png, result, _ = redraw(args.path, out=out, force=args.force)
    except (OSError, ValueError) as e:
        return _error(e)
    _say(
        f"redrew {result.scene.kind} scene {result.scene.name!r} (computed by hovering "
        f"{result.meta.get('version')}) without computing: wrote {png}"
    )
    return 0


def _accuracy(args) -> int:
    import json
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    from ._io.output import output_path, refuse_foreign, savefig, write_text
    from ._io.provenance import provenance
    from .diagnostics import work_precision
    from .flow.section import Section
    from .scenes import load_scene
    from .scenes.compute import scene_map
    from .scenes.spec import FlowScene

    try:
        scene = load_scene(args.path, check_output=False)
        out = output_path("--out", args.out if args.out is not None else f"accuracy_{Path(args.path).stem}.png")
        side = Path(out).with_suffix(".json")
        refuse_foreign([out, side], args.force)
    except (OSError, ValueError) as e:
        return _error(e)
    t0 = time.perf_counter()
    try:
        target = Section(scene.system.build(), scene.h) if isinstance(scene, FlowScene) else scene_map(scene)
        kw = {}
        if isinstance(target, Section):
            import importlib.util

            # the independent scipy curve whenever scipy is there (it is optional)
            kw["external"] = tuple(e for e in ("scipy", "heyoka") if importlib.util.find_spec(e))
        wp = work_precision(target, quick=args.quick, **kw)
    except ValueError as e:
        return _error(e)
    fig = wp.plot()
    # "format" first: how a later run recognises the table as one it may replace
    table = {"format": "hovering-accuracy-1", "provenance": provenance(), **wp.to_dict()}
    try:
        write_text(side, json.dumps(table, indent=1))
        savefig(fig, out, dpi=110)  # last: a figure on disk has its table beside it
    except (OSError, ValueError) as e:
        return _error(e)
    print(wp.format())
    _say(f"wrote {out} and {side} in {time.perf_counter() - t0:.1f} s")
    return 0


def _explore(args) -> int:
    try:
        from .explore import main as explore_main
    except ImportError as e:  # pragma: no cover - the explorer ships with the package
        return _error(e)
    argv = [args.path] + ([] if args.n_steps is None else ["--n-steps", str(args.n_steps)])
    return explore_main(argv)


def main(argv=None) -> int:
    """Entry point of ``hovering`` and ``python -m hovering``.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status (0 success, 2 bad input).
    """
    from ._version import __version__

    p = argparse.ArgumentParser(prog="hovering", description=__doc__.split("\n\n")[0])
    p.add_argument("--version", action="version", version=f"hovering {__version__}")
    loud = p.add_mutually_exclusive_group()
    loud.add_argument(
        "-v", "--verbose", action="count", default=0, help="show the package's log on stderr (-vv: also debug records)"
    )
    loud.add_argument("-q", "--quiet", action="store_true", help="print only the numbers and errors")
    sub = p.add_subparsers(dest="cmd", required=True)

    def progress_flags(sp):
        g = sp.add_mutually_exclusive_group()
        g.add_argument(
            "--progress",
            dest="progress",
            action="store_true",
            default=None,
            help="progress bars on stderr (default: when stderr is a terminal)",
        )
        g.add_argument("--no-progress", dest="progress", action="store_false")

    def force_flag(sp):
        sp.add_argument(
            "--force",
            action="store_true",
            help="replace existing output files even if hovering did not write them (default: refuse)",
        )

    d = sub.add_parser("demo", help="the packaged demo scene: the flow's return map beside its truncated model")
    d.add_argument("--out", default="hovering_demo.png", help="output PNG (default %(default)s)")
    d.add_argument(
        "--eps", type=_checked(float, -0.2, 0.2), default=-0.05, help="eps in [-0.2, 0.2] (default %(default)s)"
    )
    # The flags are named as the scene keys and the API (n_orbits, n_steps; explore --n-steps).
    d.add_argument(
        "--n-orbits",
        type=_checked(int, 1, 1000),
        default=None,
        help=f"initial conditions on L1, 1..1000 (default {_DEMO_DEFAULTS['n_orbits']})",
    )
    d.add_argument(
        "--n-steps",
        type=_checked(int, 1, 1_000_000),
        default=None,
        help=f"returns per orbit, 1..1e6 (default {_DEMO_DEFAULTS['n_steps']})",
    )
    for old, hi in (("--orbits", 1000), ("--steps", 1_000_000)):
        d.add_argument(old, dest="old_" + _dest(_DEMO_RENAMED[old]), type=_checked(int, 1, hi), help=argparse.SUPPRESS)
    d.add_argument(
        "--dpi", type=_checked(int, 30, 1200), default=130, help="PNG resolution, 30..1200 (default %(default)s)"
    )
    progress_flags(d)
    force_flag(d)
    sc = sub.add_parser("scene", help="make one figure from a scene file (examples/scenes/*.toml)")
    sc.add_argument("path", help="scene file (TOML)")
    sc.add_argument(
        "--out",
        default=None,
        help="output PNG (default: the scene's 'output', which must lie under the scene's folder or the "
        "working directory); the result NPZ + JSON are written next to it",
    )
    sc.add_argument(
        "--quick", action="store_true", help="divide the iterate counts by 50 (a fast check, not the paper's figure)"
    )
    sc.add_argument(
        "--workers",
        type=_checked(int, 1, 4096),
        default=None,
        help="sweep scenes: run N points at a time on threads of this process (1..4096)",
    )
    sc.add_argument(
        "--dask",
        action="store_true",
        help="with --workers: a Dask LocalCluster of N worker processes instead of threads",
    )
    sc.add_argument("--scheduler", default=None, help="sweep scenes: run the points on the Dask scheduler at ADDRESS")
    progress_flags(sc)
    force_flag(sc)
    pl = sub.add_parser("plan", help="the resolved sweep plan of a sweep scene, for hovering_sweep --plan")
    pl.add_argument("path", help="scene file (TOML) of kind hovering_area or flow_hovering_area")
    pl.add_argument("-o", "--out", default=None, help="plan file (default: SCENE.plan.toml in the working directory)")
    pl.add_argument("--quick", action="store_true", help="the counts of a --quick run (divided by 50)")
    force_flag(pl)
    rd = sub.add_parser("redraw", help="redraw a saved result (RESULT.npz) without computing")
    rd.add_argument("path", help="result file written by 'scene' (NPZ)")
    rd.add_argument("--out", default=None, help="output PNG (default: RESULT.png)")
    force_flag(rd)
    ac = sub.add_parser("accuracy", help="work-precision diagram of a scene's system (error vs time per setting)")
    ac.add_argument("path", help="scene file (TOML)")
    ac.add_argument("--quick", action="store_true", help="fewer settings, points and returns (seconds, not minutes)")
    ac.add_argument(
        "--out", default=None, help="output PNG (default accuracy_<scene>.png); the table goes next to it as JSON"
    )
    force_flag(ac)
    ex = sub.add_parser("explore", help="click to launch orbits on a scene's map (interactive backend)")
    ex.add_argument("path", help="scene file (TOML)")
    ex.add_argument("--n-steps", type=_checked(int, 1, 10_000_000), default=None, help="iterates per launched orbit")
    args = p.parse_args(argv)
    global _quiet
    _quiet = args.quiet
    _logging(args.verbose, args.quiet)
    if args.cmd == "demo":
        _demo_flags(p, args)
    return {
        "demo": _demo,
        "scene": _scene,
        "plan": _plan,
        "redraw": _redraw,
        "accuracy": _accuracy,
        "explore": _explore,
    }[args.cmd](args)
