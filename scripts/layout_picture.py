#!/usr/bin/env python3
"""Draw a Python package's import graph as floors: every module stands above all it imports (imports
made inside functions counted); modules that import each other in a loop are drawn in red, with the
arrows that close the loop. Used for the before/after pictures of docs/internals.md.

Usage: layout_picture.py PACKAGE_DIR OUT.png [--title TITLE]
(e.g. ``python scripts/layout_picture.py python/hovering docs/internals/layout-after.png``; for the
picture of an older commit, check it out with ``git worktree add`` and point PACKAGE_DIR there).
"""

from __future__ import annotations

import argparse
import ast
import sys
from pathlib import Path


def import_graph(package: Path) -> tuple[dict, dict]:
    """``(graph, lines)``: module -> the package's modules it imports; module -> its line count."""
    mods = {}
    for f in sorted(package.rglob("*.py")):
        name = ".".join(f.relative_to(package.parent).with_suffix("").parts)
        mods[name.removesuffix(".__init__")] = f
    graph, lines = {}, {}
    for name, f in mods.items():
        text = f.read_text()
        lines[name] = text.count("\n")
        is_pkg = f.name == "__init__.py"
        deps = set()
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = name.split(".") if is_pkg else name.split(".")[:-1]
                    base = base[: len(base) - node.level + 1]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                for a in node.names:
                    t = f"{mod}.{a.name}" if f"{mod}.{a.name}" in mods else mod
                    if t in mods:
                        deps.add(t)
            elif isinstance(node, ast.Import):
                deps.update(a.name for a in node.names if a.name in mods)
        # The package itself (its __init__) imports every layer; a submodule's `from . import
        # _core` names the package but reaches the compiled core: not an arrow.
        graph[name] = deps - {name, package.name}
    return graph, lines


def components(graph: dict) -> list:
    """Strongly connected components (Tarjan), each a sorted list."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
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
            out.append(sorted(comp))

    sys.setrecursionlimit(10_000)
    for v in graph:
        if v not in index:
            visit(v)
    return out


def floors(graph: dict) -> tuple[dict, set]:
    """Floor of each module (1 + the highest floor it imports, loops condensed) and the set of
    modules that sit in a loop."""
    comps = components(graph)
    of = {m: i for i, c in enumerate(comps) for m in c}
    looped = {m for c in comps if len(c) > 1 for m in c}
    level: dict = {}

    def lv(i):
        if i not in level:
            level[i] = 0
            deps = {of[w] for m in comps[i] for w in graph[m]} - {i}
            level[i] = 1 + max((lv(j) for j in deps), default=-1)
        return level[i]

    return {m: lv(of[m]) for m in graph}, looped


def draw(package: Path, out: Path, title: str) -> None:
    """Draw the picture into ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    graph, lines = import_graph(package)
    graph = {m: d for m, d in graph.items() if m != package.name}
    graph = {m: d & graph.keys() for m, d in graph.items()}
    fl, looped = floors(graph)
    n_floors = max(fl.values()) + 1
    rows = {f: sorted((m for m in graph if fl[m] == f), key=lambda m: (m.count("."), m)) for f in range(n_floors)}
    width = max(len(r) for r in rows.values())
    fig, ax = plt.subplots(figsize=(max(12, 1.35 * width), 0.9 * n_floors + 1.5))
    pos = {}
    for f, mods in rows.items():
        for i, m in enumerate(mods):
            pos[m] = ((i + 0.5) * width / max(len(mods), 1), f)
    n_back = 0
    for m, deps in graph.items():
        for d in deps:
            (x0, y0), (x1, y1) = pos[m], pos[d]
            loop = m in looped and d in looped and fl[m] == fl[d]
            n_back += loop
            ax.annotate(
                "",
                xy=(x1, y1 + 0.18),
                xytext=(x0, y0 - 0.18),
                arrowprops=dict(
                    arrowstyle="-|>",
                    lw=1.2 if loop else 0.5,
                    color="#c44e52" if loop else "0.7",
                    alpha=0.9 if loop else 0.5,
                    shrinkA=0,
                    shrinkB=0,
                    connectionstyle="arc3,rad=0.25" if loop else "arc3",
                ),
            )
    for m, (x, y) in pos.items():
        short = m.removeprefix(package.name + ".")
        ax.text(
            x,
            y,
            f"{short}\n{lines[m]}",
            ha="center",
            va="center",
            fontsize=6.5,
            bbox=dict(
                boxstyle="round,pad=0.25",
                fc="#f4c7c3" if m in looped else "#dce6f2",
                ec="#c44e52" if m in looped else "#4c72b0",
                lw=0.8,
            ),
        )
    ax.set_xlim(-0.3, width + 0.3)
    ax.set_ylim(-0.7, n_floors - 0.3)
    ax.set_yticks(range(n_floors), [f"floor {f + 1}" for f in range(n_floors)], fontsize=7)
    ax.set_xticks([])
    for s in ("top", "right", "bottom"):
        ax.spines[s].set_visible(False)
    n_loops = sum(1 for c in components(graph) if len(c) > 1)
    ax.set_title(
        f"{title}: {len(graph)} modules, {sum(lines.values())} lines, {n_floors} floors, "
        f"{n_loops} import cycle(s) (red), arrows = imports (inside functions too)",
        fontsize=9,
    )
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("package", type=Path)
    p.add_argument("out", type=Path)
    p.add_argument("--title", default=None)
    a = p.parse_args(argv)
    draw(a.package, a.out, a.title or a.package.name)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
