"""A scene kind is one declaration (issue 29): its spec, computation, result, summary and report in
``scenes/kinds/<kind>.py``, its figure in ``plot/kinds/<kind>.py``, one registry.

Oracles: a toy kind written as those two files (and an example scene) and nothing else, which must
then load, compute, report and draw like any kind, in a temporary package and inside a copy of
the package (where it is also saved and redrawn by the command line); the dataclass fields of each
registered spec, whose defaults are the only copy the reader may apply; the old schema's habit of
writing a default in the reader (``x if "key" in table else 400``), which no module may have again.
"""

from __future__ import annotations

import ast
import copy
import dataclasses
import importlib
import os
import shutil
import subprocess
import sys
import textwrap
import tomllib
import typing
from dataclasses import MISSING
from pathlib import Path

import numpy as np
import pytest

import hovering
from hovering import scenes
from hovering._io import serial as _serial
from hovering.plot import common, render
from hovering.plot.style import QUICK_MARK
from hovering.scenes import compute, format_summary, load_scene, parse_scene, registry
from hovering.scenes.compute import scene_map
from hovering.scenes.fields import PARAM, Param, declared
from hovering.scenes.spec import IntegratorSpec, OutputsSpec

ROOT = Path(__file__).resolve().parents[2]
SCENE_DIR = ROOT / "examples" / "scenes"
EXAMPLES = sorted(SCENE_DIR.glob("*.toml")) + [scenes.packaged_scene("demo")]

# The toy kind: its spec reuses the flow's shared tables ([system], [section], [integrator],
# [outputs]) and declares three keys of its own; it iterates the flow's return map from L1.
TOY_KIND = textwrap.dedent(
    '''
    """A toy scene kind: a few orbits of the flow's return map started on its L1."""

    from __future__ import annotations

    from dataclasses import dataclass

    import numpy as np

    from hovering.scenes.base import SceneResult, check_array
    from hovering.scenes.fields import integer, pair
    from hovering.scenes.kinds._flow import FlowScene, flowmap, needs_step
    from hovering.scenes.registry import Kind, register


    @dataclass(frozen=True, kw_only=True)
    class ToyScene(FlowScene):
        """The toy's keys: how many orbits, returns, and their heights."""

        n_orbits: int = integer(3, lo=1, hi=50)
        n_returns: int = integer(40, lo=1, hi=10_000)
        K0_range: tuple = pair((-0.05, 0.02))


    @dataclass(repr=False)
    class ToyResult(SceneResult):
        """The orbits."""

        phi: np.ndarray = None
        K: np.ndarray = None

        def _validate_loaded(self) -> None:
            super()._validate_loaded()
            check_array("phi", self.phi, 2)
            check_array("K", self.K, 2, shape=self.phi.shape)


    def compute(scene, ctx):
        n = ctx.scaled(scene.n_returns, floor=10)
        ctx.meta["n_steps"] = n
        stages = ctx.stages(1)
        stages.start("flow", f"{scene.n_orbits} orbits x {n} returns")
        fm = flowmap(scene)
        K0 = np.linspace(scene.K0_range[0], scene.K0_range[1], scene.n_orbits)
        res = fm.iterate(fm.L1(K0), K0, n, **ctx.progress_kw)
        stages.end()
        return ToyResult(scene=scene, meta=ctx.meta, phi=np.asarray(res.phi), K=np.asarray(res.K))


    def summarize(result):
        return {"K_min": float(np.nanmin(result.K)), "K_max": float(np.nanmax(result.K))}


    def report(summary):
        return [f"  K from {summary['K_min']:.5f} to {summary['K_max']:.5f}"]


    KIND = register(
        Kind(
            "toy",
            ToyScene,
            ToyResult,
            compute,
            summarize,
            report,
            doc="a toy: orbits of the flow's return map",
            figsize=(5.0, 4.0),
            records=(("regions",), ()),
            check=needs_step,
            scene_map=flowmap,
        )
    )
    '''
)

TOY_FIGURE = textwrap.dedent(
    '''
    """The toy kind's figure: its orbits in (phi, K)."""

    from hovering.plot.common import draws, grid, quick_mark
    from hovering.scenes.spec import figure_inches


    @draws("toy")
    def figure(result):
        fig, (ax,) = grid(1, None, figure_inches(result.scene))
        for i in range(result.phi.shape[0]):
            ax.plot(result.phi[i], result.K[i], ".", ms=2, gid=f"orbit:{i}")
        ax.set_title(result.scene.title + quick_mark(result))
        return fig
    '''
)

TOY_EXAMPLE = textwrap.dedent(
    """
    kind = "toy"
    title = "A toy kind"
    output = "toy.png"
    n_orbits = 3
    n_returns = 40

    [system]
    V1 = { kind = "harmonic", omega = 1.0 }
    V2 = { kind = "tan", omega = 1.4, alpha = 0.7 }
    eps = -0.05
    """
)


@pytest.fixture
def toy(tmp_path, monkeypatch):
    """A temporary package ``toykinds`` holding the toy's two files (no ``__init__.py``), its example
    scene beside it, and the registries restored afterwards."""
    (tmp_path / "toykinds").mkdir()
    (tmp_path / "toykinds" / "toy.py").write_text(TOY_KIND)
    (tmp_path / "toykinds" / "toy_figure.py").write_text(TOY_FIGURE)
    (tmp_path / "toy.toml").write_text(TOY_EXAMPLE)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(registry, "_KINDS", dict(registry._KINDS))
    monkeypatch.setattr(common, "_FIGURES", dict(common._FIGURES))
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    for name in [m for m in sys.modules if m == "toykinds" or m.startswith("toykinds.")]:
        del sys.modules[name]


def test_a_kind_in_a_temporary_package_is_two_files_and_an_example(toy):
    files = sorted(
        p.relative_to(toy).as_posix() for p in toy.rglob("*") if p.is_file() and "__pycache__" not in p.parts
    )
    assert files == ["toy.toml", "toykinds/toy.py", "toykinds/toy_figure.py"]
    importlib.import_module("toykinds.toy")
    importlib.import_module("toykinds.toy_figure")
    assert "toy" in registry.names("flow") and common.figure_of("toy") is not None

    # load: its own keys and the shared tables, each default the declaration's
    scene = load_scene(toy / "toy.toml")
    assert type(scene).__name__ == "ToyScene" and scene.name == "toy" and scene.kind == "toy"
    assert (scene.n_orbits, scene.n_returns, scene.K0_range) == (3, 40, (-0.05, 0.02))
    assert scene.system.eps == -0.05 and scene.system.geometry == "step" and scene.h == 1.0
    assert scene.integrator == IntegratorSpec() and scene.outputs == OutputsSpec(record=("regions",))
    assert scene_map(scene).h == 1.0

    # compute -> report -> draw
    result = compute(scene, quick=True)
    assert type(result).__name__ == "ToyResult" and result.phi.shape == (3, 11)  # 40 // 50 -> floor 10
    assert result.meta["kind"] == "toy" and result.meta["timings"]["flow"] >= 0
    summary = result.summary()
    assert summary["kind"] == "toy" and summary["n_steps"] == 10 and summary["K_min"] <= summary["K_max"]
    text = format_summary(summary)
    assert text.splitlines()[0] == "scene toy (toy), 10 iterates [quick]"
    assert text.splitlines()[1].startswith("  K from ")
    fig = render(result)
    try:
        (ax,) = fig.axes
        assert sorted(ln.get_gid() for ln in ax.lines) == ["orbit:0", "orbit:1", "orbit:2"]
        assert tuple(fig.get_size_inches()) == (5.0, 4.0)  # the kind's declared figure size
        assert ax.get_title() == "A toy kind" + QUICK_MARK
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)

    # bad input is named like any kind's: the key, the value, what is allowed
    good = tomllib.loads(TOY_EXAMPLE)
    for change, texts in (
        (("n_orbits", 0), ["toy.toml.n_orbits = 0 is out of range; allowed: [1, 50]"]),
        (("K0_range", [0.1, -0.1]), ["toy.toml.K0_range = [0.1, -0.1] must be increasing"]),
        (
            ("bogus", 1),
            ["unknown key(s) 'bogus'", "system, section, integrator, outputs, n_orbits, n_returns, K0_range"],
        ),
    ):
        d = dict(good, **{change[0]: change[1]})
        with pytest.raises(ValueError) as e:
            parse_scene(d, toy / "toy.toml")
        for t in texts:
            assert t in str(e.value), str(e.value)
    d = copy.deepcopy(good)
    d["system"]["geometry"] = "none"
    with pytest.raises(ValueError, match=r"toy.toml.system.geometry = 'none': a toy scene draws the regions"):
        parse_scene(d, toy / "toy.toml")
    d = copy.deepcopy(good)
    d["outputs"] = {"record": ["trajectory"]}
    with pytest.raises(ValueError, match=r"toy.toml.outputs.record = 'trajectory' is not allowed; allowed: 'regions'"):
        parse_scene(d, toy / "toy.toml")


def test_a_kind_added_to_the_package_is_two_files_and_an_example(tmp_path):
    # The same two files dropped into a copy of the package (scenes/kinds/toy.py, plot/kinds/toy.py)
    # are found without any other edit: listed, run, saved, summarized and redrawn by the command line.
    src = tmp_path / "src"
    shutil.copytree(Path(hovering.__file__).parent, src / "hovering", ignore=shutil.ignore_patterns("__pycache__"))
    (src / "hovering" / "scenes" / "kinds" / "toy.py").write_text(TOY_KIND)
    (src / "hovering" / "plot" / "kinds" / "toy.py").write_text(TOY_FIGURE)
    (tmp_path / "toy.toml").write_text(TOY_EXAMPLE)
    env = {**os.environ, "PYTHONPATH": str(src)}

    def run(*args):
        r = subprocess.run([sys.executable, *args], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stdout + r.stderr
        return r.stdout

    out = run("-c", "import hovering.scenes as s; print(s.KINDS, s.load_scene('toy.toml').__module__)")
    assert "'toy'" in out and "hovering.scenes.kinds.toy" in out
    out = run("-m", "hovering", "scene", "toy.toml", "--quick", "--out", "out/toy.png", "--no-progress")
    assert "scene toy (toy), 10 iterates [quick]" in out and "K from" in out
    for suffix in (".png", ".npz", ".json"):
        assert (tmp_path / "out" / f"toy{suffix}").stat().st_size > 0
    run("-m", "hovering", "redraw", "out/toy.npz", "--out", "out/again.png")
    assert (tmp_path / "out" / "again.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ------------------------------------------------------------------------------------------------
# Each default written once, and applied by the reader from there


def _examples_by_kind() -> dict:
    out: dict = {}
    for p in EXAMPLES:
        out.setdefault(tomllib.loads(p.read_text())["kind"], []).append(p)
    return out


def test_every_registered_kind_has_an_example_and_a_figure():
    by_kind = _examples_by_kind()
    assert set(registry.names()) == set(by_kind) == set(scenes.KINDS)
    assert set(common.drawn_kinds()) == set(registry.names())


def _declared_default(cls, name):
    f = {f.name: f for f in dataclasses.fields(cls)}[name]
    return f.default if f.default is not MISSING else f.default_factory()


def _at(spec, where: tuple):
    for k in where:
        spec = getattr(spec, k)
    return spec


def _check_defaults(spec_cls, kind, where: tuple, base: dict, path: Path) -> int:
    """Take each optional key of the table at ``where`` out alone: the spec must then hold the
    dataclass's default of that field (or, for a default by rule, the rule's value). Returns how
    many keys were checked; goes into the tables the declaration reads (``[system]``, ...)."""
    table = _at_table(base, where)
    full = parse_scene(base, path, check_output=False)
    checked = 0
    for d in declared(spec_cls, kind.name):
        key = d.param.in_table or d.param.key or d.name
        if d.param.context or d.param.required or key not in table or d.name in kind.sets:
            continue
        data = copy.deepcopy(base)
        del _at_table(data, where)[key]
        try:
            spec = parse_scene(data, path, check_output=False)
        except ValueError as e:
            # A default that the file's other keys rule out is named as any bad value is.
            assert key in str(e) or (where and where[-1] in str(e)), (where, key, str(e))
            continue
        got = getattr(_at(spec, where), d.name)
        if d.name == "title":
            assert got == path.stem  # its rule: the scene's name
        elif isinstance(d.param.default_from, str):
            assert got == getattr(_at(spec, where), d.param.default_from), (where, d.name)
        elif dataclasses.is_dataclass(got):
            # An absent table is read as an empty one: each field its own default (or its rule's).
            for f in declared(type(got), kind.name):
                if f.param.default_from is None:
                    assert getattr(got, f.name) == _declared_default(type(got), f.name), (key, f.name)
        elif d.param.default_from is None:
            assert got == _declared_default(spec_cls, d.name), (where, d.name, got)
        checked += 1
        inner = getattr(_at(full, where), d.name)
        if isinstance(table[key], dict) and dataclasses.is_dataclass(inner) and d.param.in_table is None:
            checked += _check_defaults(type(inner), kind, where + (key,), base, path)
    return checked


def _at_table(data: dict, where: tuple) -> dict:
    for k in where:
        data = data[k]
    return data


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_the_reader_applies_each_declared_default(path):
    base = tomllib.loads(path.read_text())
    kind = registry.get(base["kind"])
    assert _check_defaults(kind.spec, kind, (), base, path) > 0


def test_outputs_record_defaults_to_what_the_kind_draws():
    for name in registry.names("flow"):
        kind = registry.get(name)
        path = _examples_by_kind()[name][0]
        data = tomllib.loads(path.read_text())
        data.pop("outputs", None)
        spec = parse_scene(data, path, check_output=False)
        allowed, required = kind.records
        assert set(required) <= set(spec.outputs.record) <= set(allowed), name
        assert ("regions" in spec.outputs.record) == ("regions" in allowed), name


def test_a_param_holds_no_default():
    # The metadata says what is allowed; the default lives in the dataclass field alone.
    assert "default" not in {f.name for f in dataclasses.fields(Param)}
    for name in registry.names():
        kind = registry.get(name)
        for cls in _declared_classes(kind.spec):
            for f in dataclasses.fields(cls):
                if PARAM in f.metadata:
                    assert isinstance(f.metadata[PARAM], Param), (cls.__name__, f.name)


def _declared_classes(cls, seen=None) -> list:
    """A spec class and every dataclass its declared fields read as tables."""
    seen = seen if seen is not None else []
    if cls in seen:
        return seen
    seen.append(cls)
    hints = typing.get_type_hints(cls)
    for f in dataclasses.fields(cls):
        t = hints.get(f.name)
        if isinstance(t, type) and dataclasses.is_dataclass(t) and PARAM in f.metadata:
            _declared_classes(t, seen)
    return seen


def _defaults_in_readers(source: str) -> list:
    """Expressions ``value if "key" in table else <literal>``: a default written in a reader."""
    out = []
    for n in ast.walk(ast.parse(source)):
        if not (isinstance(n, ast.IfExp) and isinstance(n.test, ast.Compare)):
            continue
        t = n.test
        literal = isinstance(n.orelse, ast.Constant) and not isinstance(n.orelse.value, str)
        literal |= isinstance(n.orelse, (ast.Tuple, ast.List)) and all(
            isinstance(x, ast.Constant) for x in n.orelse.elts
        )
        if (
            literal
            and isinstance(t.left, ast.Constant)
            and isinstance(t.left.value, str)
            and isinstance(t.ops[0], ast.In)
        ):
            out.append(f"line {n.lineno}: {ast.unparse(n)[:100]}")
    return out


def test_no_reader_writes_a_default():
    # The old schema (9dfe78c) applied 32 defaults this way beside the dataclass's own copy (and a
    # dozen more as arguments and assignments); the pattern is recognised, and no module of the
    # scene layer has it any more.
    assert _defaults_in_readers('x = integer(d["n"]) if "n" in d else 400\n')
    package = Path(scenes.__file__).parent
    found = {p.relative_to(package).as_posix(): _defaults_in_readers(p.read_text()) for p in package.rglob("*.py")}
    assert {k: v for k, v in found.items() if v} == {}


# ------------------------------------------------------------------------------------------------
# The registry


def test_each_kinds_classes_are_saved_under_a_name_that_reads_back():
    # What a result file names (module:class) leads back to the class, for every class a kind's
    # spec and result hold; their annotations resolve (the file's values are type-checked).
    for name in registry.names():
        kind = registry.get(name)
        for cls in _declared_classes(kind.spec) + [kind.result]:
            typing.get_type_hints(cls)
            saved = _serial._type_name(cls)
            assert _serial._resolve(saved, "dataclass") is cls, saved


def test_a_kind_name_is_registered_once():
    kind = registry.get("tangent_tori")
    other = dataclasses.replace(kind, spec=type("Elsewhere", (kind.spec,), {"__module__": "elsewhere"}))
    with pytest.raises(ValueError, match="'tangent_tori' is already registered by hovering.scenes.kinds.tangent_tori"):
        registry.register(other)
    assert registry.get("tangent_tori") is kind
    with pytest.raises(ValueError, match=r"no scene kind 'movie'; allowed: 'critical_orbits', 'hovering_area'"):
        registry.get("movie")


def test_the_old_names_of_each_kind_are_its_declarations():
    from hovering.scenes import results, spec

    for name in registry.names():
        kind = registry.get(name)
        assert getattr(spec, kind.spec.__name__) is kind.spec
        assert getattr(results, kind.result.__name__) is kind.result
        assert kind.spec.__module__.startswith("hovering.scenes.kinds.")
    assert np.all([registry.get(k).sweep == (k in scenes.SWEEP_KINDS) for k in scenes.KINDS])
