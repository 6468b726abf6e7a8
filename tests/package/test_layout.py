"""The house's rules, checked: arrows only point down (import-linter's layers contract of
pyproject.toml, and no import cycle even counting imports made inside functions), and
``import hovering`` stays light (no matplotlib, dask or scene pipeline)."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "python" / "hovering"


def _import_graph() -> dict:
    """module -> modules of the package it imports, every import statement counted (those inside
    functions too; none is under TYPE_CHECKING here)."""
    mods = {}
    for f in PACKAGE.rglob("*.py"):
        name = ".".join(f.relative_to(PACKAGE.parent).with_suffix("").parts)
        mods[name.removesuffix(".__init__")] = f
    graph = {}
    for name, f in mods.items():
        is_pkg = f.name == "__init__.py"
        deps = set()
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = name.split(".") if is_pkg else name.split(".")[:-1]
                    base = base[: len(base) - node.level + 1]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                for a in node.names:
                    target = f"{mod}.{a.name}" if f"{mod}.{a.name}" in mods else mod
                    if target in mods:
                        deps.add(target)
            elif isinstance(node, ast.Import):
                deps.update(a.name for a in node.names if a.name in mods)
        graph[name] = deps - {name}
    return graph


def _cycles(graph: dict) -> list:
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_no_import_cycles_even_inside_functions():
    # The package's own modules only; `hovering` (the package itself) imports every layer, and
    # a submodule's `from . import _core` reaches the compiled core, not the package.
    graph = {m: {d for d in deps if d != "hovering"} for m, deps in _import_graph().items()}
    assert _cycles(graph) == []


def test_the_checker_sees_a_cycle_made_inside_a_function():
    # The check above could not fail if it missed function-level imports: feed it one.
    graph = _import_graph()
    graph["hovering.truncated.theory"] = graph["hovering.truncated.theory"] | {"hovering.scenes.spec"}
    graph = {m: {d for d in deps if d != "hovering"} for m, deps in graph.items()}
    assert any("hovering.truncated.theory" in c for c in _cycles(graph))


def test_layers_contract_is_kept():
    # import-linter's "layers" contract of pyproject.toml: a lower layer never imports a higher one.
    r = subprocess.run([sys.executable, "-c", "import sys; from importlinter.cli import lint_imports_command; "
                        "sys.exit(lint_imports_command())"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]
    assert "Arrows point down KEPT" in r.stdout


def test_import_hovering_is_light():
    code = ("import sys, json, hovering; "
            "print(json.dumps(sorted(m for m in sys.modules if m.split('.')[0] in "
            "('hovering', 'matplotlib', 'dask', 'distributed', 'scipy', 'tqdm'))))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    loaded = set(json.loads(r.stdout))
    heavy = {m for m in loaded if m.split(".")[0] in ("matplotlib", "dask", "distributed", "scipy")}
    assert not heavy, sorted(heavy)
    pipeline = {m for m in loaded if m.startswith(("hovering.scenes", "hovering.plot", "hovering.pipeline"))}
    assert not pipeline, sorted(pipeline)
