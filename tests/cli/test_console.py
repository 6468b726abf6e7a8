"""The ``hovering`` console script (issue 21, item 4): installed with the package, the same command
line as ``python -m hovering``, with ``--version``; ``-v`` / ``-q`` set what the package's
``logging`` shows; outside the command line the package logs and never prints.
"""

from __future__ import annotations

import ast
import logging
import pathlib
import re
import subprocess
import sys

import matplotlib.pyplot as plt
import pytest

import hovering
from hovering.cli import main

PACKAGE = pathlib.Path(hovering.__file__).resolve().parent
SCENE = pathlib.Path(__file__).resolve().parents[2] / "examples" / "scenes" / "fig_hov_vs_eps.toml"


def _script() -> str:
    # pip puts console scripts beside the interpreter of the environment it installs into
    path = pathlib.Path(sys.executable).parent / "hovering"
    assert path.exists(), f"no console script {path}: pyproject's [project.scripts] must install it"
    return str(path)


def _run(*argv):
    return subprocess.run(list(argv), capture_output=True, text=True, timeout=300)


def test_console_script_and_python_m_agree_on_version_and_help():
    script = _run(_script(), "--version")
    module = _run(sys.executable, "-m", "hovering", "--version")
    assert script.returncode == module.returncode == 0
    assert script.stdout.strip() == module.stdout.strip() == f"hovering {hovering.__version__}"
    helps = [_run(_script(), "--help"), _run(sys.executable, "-m", "hovering", "--help")]
    assert helps[0].stdout == helps[1].stdout
    for cmd in ("demo", "scene", "plan", "redraw", "accuracy", "explore", "--verbose", "--quiet"):
        assert cmd in helps[0].stdout, cmd


def test_verbose_shows_the_package_log_and_quiet_only_the_numbers(tmp_path, capsys):
    argv = ["scene", str(SCENE), "--quick", "--workers", "2", "--no-progress", "--force"]
    try:
        assert main(["-v", *argv, "--out", str(tmp_path / "a.png")]) == 0
        out = capsys.readouterr()
        assert "hovering.parallel.executor: INFO:" in out.err and "threads of this process" in out.err
        assert main([*argv, "--out", str(tmp_path / "b.png")]) == 0
        assert "INFO" not in capsys.readouterr().err  # warnings only, by default
        demo = ["demo", "--n-steps", "100", "--n-orbits", "3", "--dpi", "30", "--no-progress"]
        assert main([*demo, "--out", str(tmp_path / "c.png")]) == 0
        assert "demo done in" in capsys.readouterr().out
        assert main(["-q", *demo, "--out", str(tmp_path / "d.png")]) == 0
        out = capsys.readouterr()
        assert "demo done in" not in out.out and "scene demo (flow_portrait)" in out.out and out.err == ""
    finally:
        main_level = logging.getLogger("hovering")
        for h in [h for h in main_level.handlers if getattr(h, "_hovering_cli", False)]:
            main_level.removeHandler(h)
        main_level.setLevel(logging.NOTSET)
        plt.close("all")


def test_version_loads_neither_the_core_nor_numpy():
    # `hovering --version` answers from the package's metadata: neither the compiled core nor numpy
    # (seconds of imports) is loaded, through the console script's path (`from hovering.cli import
    # main`) or python -m's (`import hovering`, then its __main__).
    code = (
        "import json, sys\n"
        "from hovering.cli import main\n"
        "try:\n"
        "    main(['--version'])\n"
        "except SystemExit as e:\n"
        "    assert e.code == 0, e.code\n"
        "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('numpy', 'matplotlib') or m == 'hovering._core')\n"
        "print(json.dumps(heavy), file=sys.stderr)\n"
    )
    r = _run(sys.executable, "-c", code)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"hovering {hovering.__version__}"
    assert r.stderr.strip().splitlines()[-1] == "[]", r.stderr
    # the same through `python -m hovering`, checked from inside the run (at exit)
    atexit = (
        "import atexit, runpy, sys\n"
        "atexit.register(lambda: print(sorted(m for m in sys.modules if m.split('.')[0] == 'numpy' "
        "or m == 'hovering._core'), file=sys.stderr))\n"
        "sys.argv = ['hovering', '--version']\n"
        "runpy.run_module('hovering', run_name='__main__', alter_sys=True)\n"
    )
    r = _run(sys.executable, "-c", atexit)
    assert r.stdout.strip() == f"hovering {hovering.__version__}" and r.stderr.strip().splitlines()[-1] == "[]", (
        r.stdout + r.stderr
    )
    # and the version is the build's own: what the compiled core says it is
    assert hovering.__version__ == dict(hovering._core.build_info())["hovering"]


def test_version_metadata_of_another_copy_or_none_falls_back_to_the_core(monkeypatch, tmp_path):
    # The metadata is this copy's only if its files are these files: a source tree on sys.path
    # beside another installed hovering (another version) reads the version the core was built with.
    from importlib import metadata

    from hovering import _version

    core = dict(hovering._core.build_info())["hovering"]

    class Elsewhere:
        version = "9.9.9"

        def locate_file(self, path):
            return tmp_path / path

    monkeypatch.setattr(metadata, "distribution", lambda name: Elsewhere())
    assert _version._read() == core

    def missing(name):
        raise metadata.PackageNotFoundError(name)

    monkeypatch.setattr(metadata, "distribution", missing)
    assert _version._read() == core


def _cli_log_handlers_removed():
    log = logging.getLogger("hovering")
    for h in [h for h in log.handlers if getattr(h, "_hovering_cli", False)]:
        log.removeHandler(h)
    log.setLevel(logging.NOTSET)


def test_verbose_logs_the_stages_of_a_run_and_quiet_by_default(tmp_path, capsys):
    demo = ["demo", "--n-steps", "20", "--n-orbits", "2", "--dpi", "30", "--no-progress"]
    try:
        assert main(["-v", *demo, "--out", str(tmp_path / "a.png")]) == 0
        err = capsys.readouterr().err
        stages = [ln for ln in err.splitlines() if ": stage " in ln]
        # each stage starts (what it computes, how much) and ends (its time), numbered i/n
        assert "hovering.scenes.compute: INFO: scene demo: stage 1/5 setup: " in err, err
        assert any(ln.endswith("stage 2/5 flow: 2 orbits x 20 returns") for ln in stages), stages
        assert re.search(r"scene demo: stage 5/5 corner curves done, \d+\.\d s", err), err
        assert len(stages) == 10 and re.search(r"scene demo: computed in \d+\.\d s", err)
        assert re.search(r"scene demo: figure drawn and .*a\.npz.* written, \d+\.\d s", err), err
        # without -v: none of it (the library logs at INFO; the command line shows warnings)
        assert main([*demo, "--out", str(tmp_path / "b.png")]) == 0
        assert capsys.readouterr().err == ""
    finally:
        _cli_log_handlers_removed()
        plt.close("all")
    # outside the command line the library configures nothing: no handler of its own prints
    assert all(isinstance(h, logging.NullHandler) for h in logging.getLogger("hovering").handlers)


def test_demo_old_flags_still_work_with_a_deprecation_line(tmp_path, capsys):
    try:
        argv = ["demo", "--dpi", "30", "--no-progress"]
        assert main([*argv, "--steps", "20", "--orbits", "2", "--out", str(tmp_path / "old.png")]) == 0
        out = capsys.readouterr()
        assert (
            "hovering demo --steps is deprecated and will be removed in hovering 0.4.0; use --n-steps instead"
            in out.err
        )
        assert "use --n-orbits instead" in out.err and "flow: 2 orbits" in out.out
        assert main([*argv, "--n-steps", "20", "--n-orbits", "2", "--out", str(tmp_path / "new.png")]) == 0
        new = capsys.readouterr()
        assert new.err == "" and new.out.replace("new.", "old.").split("wrote")[0] == out.out.split("wrote")[0]
        helps = _run(sys.executable, "-m", "hovering", "demo", "--help").stdout
        assert "--n-steps" in helps and "--n-orbits" in helps and "--steps" not in helps.replace("--n-steps", "")
        with pytest.raises(SystemExit):  # both names of one flag: a usage error
            main([*argv, "--steps", "20", "--n-steps", "20", "--out", str(tmp_path / "both.png")])
        assert "--steps is the old name of --n-steps: give --n-steps only" in capsys.readouterr().err
    finally:
        _cli_log_handlers_removed()
        plt.close("all")


# Where the package may print: the command line (cli.py, the explorer's own command line) and
# show_versions, whose job is printing the record; everything else logs.
ALLOWED = {("cli.py", None), ("explore.py", "main"), ("_io/provenance.py", "show_versions")}


def _prints(tree) -> list:
    """(line, name of the outermost function around it or None) of every print() call."""
    out = []

    def visit(node, where):
        for child in ast.iter_child_nodes(node):
            inner = where
            if where is None and isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                inner = child.name
            if isinstance(child, ast.Call) and getattr(child.func, "id", None) == "print":
                out.append((child.lineno, inner))
            visit(child, inner)

    visit(tree, None)
    return out


def test_the_package_prints_only_in_its_command_line():
    found = []
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE).as_posix()
        for line, name in _prints(ast.parse(path.read_text(encoding="utf-8"))):
            if (rel, None) not in ALLOWED and (rel, name) not in ALLOWED:
                found.append(f"{rel}:{line} in {name}")
    assert not found, f"print() outside the command line (use logging.getLogger(__name__)): {found}"
    # the check sees prints at all: the command line's own are found
    assert _prints(ast.parse((PACKAGE / "cli.py").read_text(encoding="utf-8")))
