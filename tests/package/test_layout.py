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


def _run(code: str) -> str:
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    return r.stdout


def test_import_hovering_loads_no_core_and_each_name_only_its_own_module():
    # `import hovering` (and `hovering --version`) load neither numpy nor any layer (the core only
    # when the version must come from it: a source tree beside another install); the first use
    # of a public name loads the module that holds it and what that imports, nothing else.
    code = (
        "import sys, json, os\n"
        "from importlib import metadata\n"
        "import hovering\n"
        "d = metadata.distribution('hovering')\n"
        "own = os.path.realpath(str(d.locate_file('hovering/_version.py'))) == os.path.realpath(hovering._version.__file__)\n"
        "def loaded(): return sorted(m for m in sys.modules if m.startswith(('hovering', 'numpy')))\n"
        "first = loaded()\n"
        "m = hovering.TruncatedMap(eps=0.2, Omega0=hovering.OMEGA_G, theta_w=2.0)\n"
        "second = loaded()\n"
        "hovering.hovering_area\n"
        "third = loaded()\n"
        "print(json.dumps([own, first, second, third, callable(hovering.explore), 'hovering_area' in dir(hovering)]))\n"
    )
    own, first, second, third, explore_is_function, listed = json.loads(_run(code))
    # the version's source (and numpy, which the core imports) only when the metadata is not this copy's
    assert ("hovering._core" in first) == (not own) and ("numpy" in first) == (not own)
    assert not [
        m
        for m in first
        if m.startswith("hovering.")
        and not m.startswith(("hovering._core", "hovering._version", "hovering._deprecated"))
    ]
    layers = ("hovering.analysis", "hovering.diagnostics", "hovering.normal", "hovering.scenes", "hovering.explore")
    assert "numpy" in second and "hovering.truncated.maps" in second and not [m for m in second if m.startswith(layers)]
    above = ("hovering.diagnostics", "hovering.scenes", "hovering.explore", "hovering.plot", "hovering.pipeline")
    assert "hovering.analysis" in third and not [m for m in third if m.startswith(above)]
    assert explore_is_function and listed


def test_every_public_name_is_the_one_api_py_imports():
    # The package's table is read from _api.py's imports: the same objects an eager import gives,
    # and hovering.explore stays the function whichever of it and its module is imported first.
    code = (
        "import json, types, warnings\n"
        "import hovering.explore, hovering\n"
        "from hovering import _api\n"
        "warnings.simplefilter('error')\n"
        "odd = [n for n in hovering.__all__ if n not in ('__version__', 'simd_width', 'geometry') and getattr(hovering, n) is not getattr(_api, n)]\n"
        "print(json.dumps([odd, len(hovering.__all__), callable(hovering.explore), sorted(set(hovering.__all__) - set(dir(_api)))]))\n"
    )
    odd, n, explore_is_function, own = json.loads(_run(code))
    assert odd == [] and n > 80 and explore_is_function
    assert own == ["__version__", "geometry", "simd_width"]


def test_the_old_module_paths_are_no_files_and_still_import():
    # The root holds the package's topics: the old paths are a table (hovering._deprecated), served
    # to the import system; each still imports, and its names warn as they are used.
    assert not [p.name for p in PACKAGE.glob("*.py") if p.stem in ("geometry", "maps", "fullmap", "sweeps")]
    code = (
        "import json, warnings\n"
        "import hovering.geometry as g\n"
        "from hovering.maps import TruncatedMap\n"
        "import hovering._pickle, hovering._io.records\n"
        "with warnings.catch_warnings(record=True) as w:\n"
        "    warnings.simplefilter('always')\n"
        "    g.K_crit\n"
        "print(json.dumps([str(w[0].message), hovering._pickle is hovering._io.records]))\n"
    )
    message, same = json.loads(_run(code))
    assert (
        message.startswith("hovering.geometry.K_crit is deprecated") and "hovering.truncated.theory.K_crit" in message
    )
    assert same
