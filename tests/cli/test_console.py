"""The ``hovering`` console script (issue 21, item 4): installed with the package, the same command
line as ``python -m hovering``, with ``--version``; ``-v`` / ``-q`` set what the package's
``logging`` shows; outside the command line the package logs and never prints.
"""

from __future__ import annotations

import ast
import logging
import pathlib
import subprocess
import sys

import matplotlib.pyplot as plt

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
        demo = ["demo", "--steps", "100", "--orbits", "3", "--dpi", "30", "--no-progress"]
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


# Where the package may print: the command line (cli.py, the explorer's own command line) and
# show_versions, whose job is printing the record; everything else logs.
ALLOWED = {("cli.py", None), ("explore.py", "main"), ("_provenance.py", "show_versions")}


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
