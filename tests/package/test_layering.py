"""No lower layer calls a higher one, through any indirection this test can see.

import-linter (tests/package/test_layout.py) sees import statements, those inside functions
included. A lower module can still reach up without one: a registry of hooks that the higher module
fills at import and the lower one calls at run time (``interface.hook("hovering_area")(m)`` did
that), a module found by name (``importlib.import_module("hovering._api")``), a function fetched from
the package's lazy table. Three checks close those doors:

* **Static**: every call that imports by name (``importlib.import_module``, ``__import__``,
  ``importlib.util.find_spec``) names, when its argument is a constant, a module its caller may
  import (one it reaches through its own imports); a name computed at run time is allowed in the few
  modules listed in ``BY_NAME``, each with its reason.
* **Dynamic**: a profiler watches every call made while the package works (maps, the flow, the
  analyses, accuracy targets, scenes, saving and loading). A call from module A into a plain
  function of module B that A cannot reach through its imports is legitimate only as a callback: the
  function object is held (in locals, arguments, closures, containers and attributes, a class's
  declarations included) by each frame up the stack until one whose module can reach B, or the
  caller's own code, handed it down. A
  function A fetched itself (from a registry, by name, through the package's ``__getattr__``) breaks
  that chain: an upward call. Method calls are dispatch on an object the caller was handed (or, in
  ``hovering._io.serial``, rebuilt from a file that names its class), not arrows, and are not
  counted. The only upward calls allowed are the deprecated forms (``m.hovering_area()``,
  ``FlowMap(accuracy=)``), made by ``hovering._deprecated.call_moved`` after it warned.
* **State**: after the whole package is imported, no module keeps a function of a module it cannot
  import (a registry filled from above), but those listed in ``HOLDERS`` with their reason. It sees
  a registry whose caller keeps the hook in a local, which the profiler lets pass.

On the commit before the hooks went (351d006) the three checks find ``interface``'s import of
``hovering._api`` by name, the four hooks called (``m.hovering_area()``, ``m.critical_curve()``,
``FlowMap(accuracy=)``, the spec's check on ``hovering.load``) and ``interface._HOOKS`` holding them.

The detector itself is tested on toy hooks (a registry, a name lookup, the lazy table), so that a
clean run means something.
"""

from __future__ import annotations

import ast
import functools
import sys
import warnings
from pathlib import Path
from types import FunctionType, MappingProxyType, ModuleType

import numpy as np
import pytest

import hovering
from hovering import paper

PACKAGE = Path(__file__).resolve().parents[2] / "python" / "hovering"

#: Modules that import by a name computed at run time, and why that is no arrow up.
BY_NAME = {
    "hovering": "the package's face: loads each public name's module at its first use (_api.py's table)",
    "hovering._deprecated": "old module paths and moved names, found as they are used (one release)",
    "hovering._io.serial": "the classes a result file names (hovering's own only: _resolve refuses others)",
    "hovering._extras": "optional third-party packages (numpy-only installs)",
    "hovering.scenes.kinds": "its own submodules (every kind registered)",
    "hovering.plot.kinds": "its own submodules (every figure registered)",
    "hovering.cli": "optional third-party packages (scipy, heyoka) for the accuracy command",
    "hovering.diagnostics.work_precision": "optional third-party packages (scipy, heyoka)",
}


# ------------------------------------------------------------------------------------ the graph


def _modules() -> dict:
    out = {}
    for p in PACKAGE.rglob("*.py"):
        parts = list(p.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = p
    return out


MODULES = _modules()


def _by_name_calls():
    """(module, line, the named module or None when computed at run time) of every import by name."""
    for name, path in MODULES.items():
        yield from _by_name_calls_in(name, path)


def _by_name_calls_in(name: str, path: Path):
    """The imports by name of one module (see :func:`_by_name_calls`)."""
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.Call) or not node.args:
            continue
        f = node.func
        fname = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
        if fname not in ("import_module", "__import__", "find_spec"):
            continue
        a = node.args[0]
        if isinstance(a, ast.Constant) and isinstance(a.value, str):
            target = a.value
        elif (
            isinstance(a, ast.JoinedStr)
            and a.values
            and isinstance(a.values[0], ast.FormattedValue)
            and getattr(a.values[0].value, "id", "") == "__name__"
        ):
            target = name + ".<its own submodule>"  # f"{__name__}.x": below the module itself
        else:
            target = None
        yield name, node.lineno, target


def _imports(name: str, path: Path) -> set:
    """The package's modules ``name`` imports (at the top or inside functions)."""
    base = name if path.name == "__init__.py" else name.rpartition(".")[0]
    deps = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                pkg = base
                for _ in range(node.level - 1):
                    pkg = pkg.rpartition(".")[0]
                target = f"{pkg}.{node.module}" if node.module else pkg
            else:
                target = node.module or ""
            # `from P import a`: the submodule P.a where there is one, else P (a name P defines)
            targets = [f"{target}.{a.name}" if f"{target}.{a.name}" in MODULES else target for a in node.names]
        # Only what the import names: importing a.b.c runs a.b's __init__ too, but a package's
        # __init__ is no bridge to what it imports for its users (hovering.scenes.base does not
        # name hovering.scenes.schema because the package imports both).
        deps.update(t for t in targets if t in MODULES)
    # A package that imports its submodules by name (scenes.kinds, plot.kinds: every kind registered)
    # imports each of them.
    if any(t == name + ".<its own submodule>" for n, _, t in _by_name_calls_in(name, path)):
        deps.update(m for m in MODULES if m.rpartition(".")[0] == name)
    deps.discard(name)
    return deps


@functools.cache
def _graph() -> dict:
    return {n: _imports(n, p) for n, p in MODULES.items()}


@functools.cache
def reach(name: str) -> frozenset:
    """Every module ``name`` can name through its imports (itself included). The package's own
    ``__init__`` is no bridge: its lazy table would make everything reachable from everything."""
    seen, todo = {name}, [name]
    while todo:
        for d in _graph().get(todo.pop(), ()):
            if d not in seen and d != "hovering":
                seen.add(d)
                todo.append(d)
    return frozenset(seen)


# ------------------------------------------------------------------------------------ static


def test_imports_by_name_name_only_modules_their_caller_may_import():
    bad = []
    for name, line, target in _by_name_calls():
        if target is None:
            if name not in BY_NAME:
                bad.append(f"{name}:{line} imports a module by a name computed at run time")
        elif target.startswith("hovering") and not target.startswith(name + "."):
            if target not in reach(name):
                bad.append(f"{name}:{line} imports {target} by name, which it does not import (an arrow up)")
    assert not bad, "\n".join(bad)


def test_the_static_scan_sees_imports_by_name():
    found = {(n, t) for n, _, t in _by_name_calls()}
    assert ("hovering._io.serial", None) in found  # the classes a file names
    assert ("hovering.scenes.kinds", "hovering.scenes.kinds.<its own submodule>") in found
    # ... and the hook registry's loader would have been caught: interface could not name _api
    assert "hovering._api" not in reach("hovering.interface")


def test_reach_follows_imports_and_stops_at_the_package_face():
    assert "hovering.analysis.hovering" in reach("hovering.scenes.kinds._sweep")
    assert "hovering.interface" in reach("hovering.analysis.hovering")
    for low, high in [
        ("hovering.interface", "hovering.analysis.hovering"),
        ("hovering.normal.flowmap", "hovering.diagnostics.tolerance"),
        ("hovering.scenes.base", "hovering.scenes.schema"),
        ("hovering._io.serial", "hovering.scenes.base"),
    ]:
        assert high not in reach(low), (low, high)


# ------------------------------------------------------------------------------------ dynamic


def _holds(root, code, depth: int = 24, budget: int = 50000) -> bool:
    """Whether ``root`` is, wraps, or holds (through containers, attributes, closures, partials and
    dataclass metadata, ``depth`` levels deep) the function of ``code``. Modules are not entered: a
    module holds everything it defines, and holding one is not being handed a function."""
    seen, todo = set(), [(root, 0)]
    while todo and budget > 0:
        obj, d = todo.pop()
        if id(obj) in seen or obj is None or isinstance(obj, (str, bytes, int, float, complex, np.ndarray, ModuleType)):
            continue
        seen.add(id(obj))
        budget -= 1
        if getattr(obj, "__code__", None) is code:
            return True
        if d >= depth:
            continue
        nxt = []
        if isinstance(obj, dict):
            nxt = list(obj.values())
        elif isinstance(obj, (list, tuple, set, frozenset)):
            nxt = list(obj)
        elif isinstance(obj, (MappingProxyType,)):
            nxt = list(obj.values())
        else:
            for a in ("__func__", "__self__", "func", "args", "keywords", "__wrapped__", "metadata"):
                if a in ("__self__",) and isinstance(obj, type):
                    continue
                v = getattr(obj, a, None) if not isinstance(obj, type) or a == "__wrapped__" else None
                if v is not None:
                    nxt.append(v)
            cells = getattr(obj, "__closure__", None)
            if isinstance(cells, tuple):
                nxt += [c.cell_contents for c in cells if _filled(c)]
            try:
                nxt += list(vars(obj).values())
            except TypeError:
                pass
            if not isinstance(obj, type):
                nxt.append(type(obj))  # what the object's class holds: dispatch on the object
        todo += [(v, d + 1) for v in nxt[:500]]
    return False


def _functions_in(root, depth: int = 8, budget: int = 20000):
    """The Python functions ``root`` holds (as :func:`_holds` searches), each once."""
    seen, todo = set(), [(root, 0)]
    while todo and budget > 0:
        obj, d = todo.pop()
        if id(obj) in seen or obj is None or isinstance(obj, (str, bytes, int, float, complex, np.ndarray, ModuleType)):
            continue
        seen.add(id(obj))
        budget -= 1
        if isinstance(obj, FunctionType):
            yield obj
        if d >= depth:
            continue
        if isinstance(obj, (dict, MappingProxyType)):
            nxt = list(obj.values())
        elif isinstance(obj, (list, tuple, set, frozenset)):
            nxt = list(obj)
        else:
            nxt = (
                [getattr(obj, a, None) for a in ("__func__", "func", "__wrapped__")]
                if not isinstance(obj, type)
                else []
            )
            cells = getattr(obj, "__closure__", None)
            if isinstance(cells, tuple):
                nxt += [c.cell_contents for c in cells if _filled(c)]
            try:
                nxt += list(vars(obj).values())
            except TypeError:
                pass
        todo += [(v, d + 1) for v in nxt[:500]]


def _filled(cell) -> bool:
    try:
        cell.cell_contents  # noqa: B018
    except ValueError:
        return False
    return True


def _is_method(frame) -> bool:
    co = frame.f_code
    return co.co_argcount > 0 and co.co_varnames[0] in ("self", "cls")


class UpwardCalls:
    """A profiler: the calls into plain functions that their caller reached by indirection."""

    def __init__(self):
        self.found: list = []

    def _check(self, frame) -> None:
        callee = frame.f_globals.get("__name__", "")
        caller_frame = frame.f_back
        if caller_frame is None or not callee.startswith("hovering"):
            return
        caller = caller_frame.f_globals.get("__name__", "")
        if not caller.startswith("hovering") or caller == callee or callee in reach(caller):
            return
        if frame.f_code.co_name == "<module>" or _is_method(frame):
            return  # an import running a module; dispatch on an object's (or a class's) type
        code = frame.f_code
        f = caller_frame
        while f is not None:
            mod = f.f_globals.get("__name__", "")
            if not mod.startswith("hovering") or callee in reach(mod):
                return  # handed down by the caller's own code, or by a module that can name it
            if not any(_holds(v, code) for v in f.f_locals.values()):
                # this frame, which cannot name the function, did not receive it: it fetched it
                self.found.append((mod, f.f_code.co_name, callee, code.co_name))
                return
            f = f.f_back

    def __call__(self, frame, event, arg):
        if event == "call":
            self._check(frame)

    def __enter__(self):
        self._old = sys.getprofile()
        sys.setprofile(self)
        return self

    def __exit__(self, *exc):
        sys.setprofile(self._old)


def _deprecated_only(found: list) -> list:
    """The upward calls not made by the deprecation module on behalf of a deprecated form."""
    return [c for c in found if not (c[0] == "hovering._deprecated" and c[1] == "call_moved")]


#: Modules that hold functions of modules above them, and why no call goes up through them.
HOLDERS = {
    "hovering": "the package's face: each public name, cached at its first use",
    "hovering.scenes.registry": "the table of scene kinds: the kinds register themselves; only modules above every "
    "kind (compute, schema, report, plan, results) call what it holds",
    "hovering.plot.common": "the table of figures: the figure modules register themselves; plot.figures.render, "
    "above them, calls them",
}


def test_no_lower_module_keeps_functions_of_a_higher_one():
    # A registry of hooks is state: after the whole package is imported, a lower module that keeps
    # (in its globals, through containers, classes, closures) a function of a module it cannot
    # import is one a higher module handed it to call later. The dynamic check misses a registry
    # whose caller keeps the fetched hook in a local: this one does not.
    import importlib

    for name in MODULES:
        importlib.import_module(name)
    bad = []
    for name in MODULES:
        if name in HOLDERS:
            continue
        mod = sys.modules[name]
        for key, value in vars(mod).items():
            for fn in _functions_in(value):
                owner = getattr(fn, "__module__", "") or ""
                if owner.startswith("hovering") and owner != name and owner in MODULES and owner not in reach(name):
                    bad.append(f"{name}.{key} holds {owner}.{fn.__qualname__}")
    assert not bad, "\n".join(sorted(set(bad)))


def test_the_state_scan_sees_a_registry(toys):
    # the toy registry (a dict in hovering.interface holding hovering.analysis.hovering_area)
    found = [fn for fn in _functions_in(hovering.interface._TOY_HOOKS) if fn.__module__ == "hovering.analysis.hovering"]
    assert found and "hovering.analysis.hovering" not in reach("hovering.interface")


# Toy hooks, in the namespaces of lower modules (their functions run as those modules' code).
_TOYS = """
_TOY_HOOKS = {}

def _toy_register(name, fn):
    _TOY_HOOKS[name] = fn

def _toy_area_through_registry(m):
    return _TOY_HOOKS["area"](m, n_steps=20, n_samples=16)

def _toy_area_through_registry_local(m):
    fn = _TOY_HOOKS["area"]
    return fn(m, n_steps=20, n_samples=16)

def _toy_area_by_name(m):
    import importlib
    return getattr(importlib.import_module("hovering.analysis"), "hovering_area")(m, n_steps=20, n_samples=16)

def _toy_area_through_the_package(m):
    import hovering
    return hovering.hovering_area(m, n_steps=20, n_samples=16)

def _toy_callback(fn, m):
    return fn(m, n_steps=20, n_samples=16)
"""


@pytest.fixture(scope="module")
def toys():
    """The toy hooks, defined in hovering.interface's namespace (the test's frames hold none of them)."""
    ns = vars(hovering.interface)
    exec(compile(_TOYS, hovering.interface.__file__, "exec"), ns)
    ns["_toy_register"]("area", hovering.analysis.hovering_area)
    yield
    for k in [k for k in ns if k.startswith(("_toy", "_TOY"))]:
        del ns[k]


@pytest.mark.parametrize("toy", ["_toy_area_through_registry", "_toy_area_by_name", "_toy_area_through_the_package"])
def test_the_detector_catches_a_lower_module_reaching_up(toys, toy):
    m = hovering.TruncatedMap(eps=0.2, Omega0=hovering.OMEGA_G, theta_w=2.0)
    with UpwardCalls() as up:
        getattr(hovering.interface, toy)(m)
    assert [c for c in up.found if c[:2] == ("hovering.interface", toy)], up.found
    assert {c[2:] for c in up.found} <= {("hovering.analysis.hovering", "hovering_area"), ("hovering", "__getattr__")}


def test_the_detector_lets_a_callback_handed_down_pass(toys):
    m = hovering.TruncatedMap(eps=0.2, Omega0=hovering.OMEGA_G, theta_w=2.0)
    with UpwardCalls() as up:
        hovering.interface._toy_callback(hovering.analysis.hovering_area, m)
    assert up.found == []


def _workload(tmp_path: Path) -> None:
    """What the package does, small: every layer at work, callbacks and dispatch included."""
    m = hovering.TruncatedMap(eps=0.2, Omega0=hovering.OMEGA_G, theta_w=3 * np.pi / 4)
    m.iterate([0.1, 0.2], [-0.05, -0.1], 50, record=("orbit", "regions", "rotation"))
    hv = hovering.hovering_area(m, n_steps=40, n_samples=64, executor=2)
    hovering.critical_curve(m, n_steps=200, n_grid=8, tol=1e-3)
    m.hovers()
    hovering.save(hv, tmp_path / "h.npz")
    hovering.load(tmp_path / "h.npz")
    fm = paper.flow_map(eps=-0.05)
    fm.returns([0.3], [-0.02])
    res = fm.iterate([0.3], [-0.02], 3, record=("orbit", "regions"))
    hovering.rotation_number(res) if res.rotation is not None else None
    hovering.hovering_area(fm, n_steps=5, n_samples=8, components=False)
    hovering.save(fm, tmp_path / "fm.npz")
    hovering.load(tmp_path / "fm.npz")
    sys0 = paper.system(eps=0.0)
    hovering.diagnostics.accurate_flow_map(sys0, 1.0, accuracy=1e-9, coordinates="section")
    scene = hovering.scenes.load_scene(PACKAGE / "scenes" / "data" / "demo.toml", check_output=False)
    result = hovering.scenes.compute(scene, quick=True)
    result.save(tmp_path / "demo.npz")
    hovering.load(tmp_path / "demo.npz")  # a scene result rebuilt by the generic loader
    hovering.scenes.load_result(tmp_path / "demo.npz")  # ... and by the scenes' own, with the schema's checks


def test_the_package_at_work_makes_no_upward_call(tmp_path):
    with UpwardCalls() as up:
        _workload(tmp_path)
    assert _deprecated_only(up.found) == [], _deprecated_only(up.found)


def test_the_deprecated_forms_reach_up_through_the_deprecation_module_only_and_warn():
    m = hovering.TruncatedMap(eps=0.2, Omega0=hovering.OMEGA_G, theta_w=2.0)
    with warnings.catch_warnings(record=True) as w, UpwardCalls() as up:
        warnings.simplefilter("always")
        m.hovering_area(n_steps=20, n_samples=16)
        hovering.FlowMap(paper.system(eps=0.0), 1.0, coordinates="section", accuracy=1e-9)
    assert {c[3] for c in up.found} == {"hovering_area", "choose_setting"}, up.found
    assert _deprecated_only(up.found) == []  # each made by _deprecated.call_moved ...
    messages = [str(x.message) for x in w if issubclass(x.category, DeprecationWarning)]
    assert any("TruncatedMap.hovering_area() is deprecated" in t for t in messages), messages
    assert any("FlowMap(accuracy=...) is deprecated" in t and "accurate_flow_map" in t for t in messages), messages
