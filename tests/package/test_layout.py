"""The house's rules, checked: arrows only point down and nothing imports in a loop (import-linter's
contracts of pyproject.toml, imports made inside functions counted), and
``import hovering`` stays light (no matplotlib, dask or scene pipeline)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "python" / "hovering"


def _lint_imports(cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    """lint-imports in ``cwd``, its report as plain text (some releases colour it even into a pipe)."""
    r = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from importlinter.cli import lint_imports_command; sys.exit(lint_imports_command())",
        ],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    r.stdout = re.sub(r"\x1b\[[0-9;]*m", "", r.stdout)
    return r


def test_the_contracts_see_a_cycle_made_inside_a_function(tmp_path):
    # The contracts below could not fail if the tool missed imports made inside functions: give it
    # a package whose only loop is one (a.f imports b, b imports a at the top).
    pkg = tmp_path / "toy"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "sub" / "a.py").write_text("def f():\n    from . import b\n    return b\n")
    (pkg / "sub" / "b.py").write_text("from . import a\n")
    (tmp_path / "pyproject.toml").write_text(
        '[tool.importlinter]\nroot_packages = ["toy"]\n\n[[tool.importlinter.contracts]]\nname = "No cycles"\n'
        'type = "acyclic_siblings"\nancestors = ["toy"]\n'
    )
    r = _lint_imports(tmp_path, env={**os.environ, "PYTHONPATH": str(tmp_path)})
    assert r.returncode == 1 and "No cycles BROKEN" in r.stdout, r.stdout[-2000:] + r.stderr[-2000:]
    assert "toy.sub" in r.stdout  # the package whose children loop


def test_layers_and_no_cycles_contracts_are_kept():
    # import-linter's contracts of pyproject.toml: a lower layer never imports a higher one, and no
    # modules of one package import each other in a loop (imports inside functions counted).
    r = _lint_imports(ROOT)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]
    assert "Arrows point down KEPT" in r.stdout and "No cycles KEPT" in r.stdout


def test_import_hovering_is_light():
    code = (
        "import sys, json, hovering; "
        "print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in "
        "('hovering', 'matplotlib', 'dask', 'distributed', 'scipy', 'tqdm'))))"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    loaded = set(json.loads(r.stdout))
    heavy = {m for m in loaded if m.split(".")[0] in ("matplotlib", "dask", "distributed", "scipy")}
    assert not heavy, sorted(heavy)
    pipeline = {m for m in loaded if m.startswith(("hovering.scenes", "hovering.plot", "hovering.pipeline"))}
    assert not pipeline, sorted(pipeline)


def test_import_hovering_loads_no_core_and_the_first_use_loads_the_api():
    # `import hovering` (and `hovering --version`) load neither numpy nor the compiled core; the
    # first use of a public name loads the API, as the eager import did; a model used straight from
    # its module finds the analyses its methods call (hooks registered on demand); hovering.explore
    # stays the function whichever of it and its module is imported first.
    code = (
        "import sys, hovering\n"
        "light = [m for m in ('numpy', 'hovering._core', 'hovering.analysis') if m in sys.modules]\n"
        "m = hovering.TruncatedMap(eps=0.2, Omega0=hovering.OMEGA_G, theta_w=2.0)\n"
        "loaded = all(m in sys.modules for m in ('numpy', 'hovering._core', 'hovering.diagnostics'))\n"
        "print(light, loaded, callable(hovering.explore), 'hovering_area' in dir(hovering))\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and r.stdout.split() == ["[]", "True", "True", "True"], r.stdout + r.stderr
    code = (
        "import hovering.explore, hovering\n"
        "from hovering.truncated import TruncatedMap\n"
        "m = TruncatedMap(eps=0.2, Omega0=2.1, theta_w=2.0)\n"
        "print(callable(hovering.explore), m.hovering_area(n_steps=40, n_samples=50).n_samples > 0)\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and r.stdout.split() == ["True", "True"], r.stdout + r.stderr
