"""Pages the docs build writes before Sphinx reads the sources: the API index (from ``__all__``)
and one gallery script per scene file (each runs its scene in quick mode)."""

from __future__ import annotations

import importlib
import tomllib
import types
from pathlib import Path

import hovering

#: Subpackages with an API page of their own, in reading order (their names not exported at the top).
SUBPACKAGES = (
    "hovering.truncated",
    "hovering.flow",
    "hovering.normal",
    "hovering.analysis",
    "hovering.diagnostics",
    "hovering.parallel",
    "hovering.scenes",
    "hovering.plot",
    "hovering.pipeline",
    "hovering.paper",
)


def public_names(module) -> list[str]:
    """The documented names of a module: its ``__all__`` without submodules and dunders."""
    out = []
    for name in getattr(module, "__all__", []):
        if name.startswith("__"):
            continue
        if isinstance(getattr(module, name, None), types.ModuleType):
            continue
        out.append(name)
    return out


def _write(path: Path, text: str) -> None:
    """Write only when the text changed (Sphinx rebuilds what is newer)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def _autosummary(module: str, names: list[str]) -> str:
    lines = [f".. currentmodule:: {module}", "", ".. autosummary::", "   :toctree: generated", ""]
    lines += [f"   {n}" for n in names]
    return "\n".join(lines) + "\n"


def write_api_pages(where: Path) -> None:
    """``api/index.rst``: the top-level names, then each subpackage's own names."""
    top = set(public_names(hovering))
    parts = [
        "API reference",
        "=============",
        "",
        "Every public name of ``hovering`` (``hovering.__all__``), then each subpackage's names that",
        "are not exported at the top level. Generated from the docstrings.",
        "",
        "``hovering``",
        "------------",
        "",
        _autosummary("hovering", sorted(top, key=str.lower)),
    ]
    for sub in SUBPACKAGES:
        mod = importlib.import_module(sub)
        own = [n for n in public_names(mod) if n not in top]
        if not own:
            continue
        title = f"``{sub}``"
        first = (mod.__doc__ or "").strip().split("\n\n")[0].replace("\n", " ")
        parts += [title, "-" * len(title), "", first, "", _autosummary(sub, sorted(own, key=str.lower))]
    _write(where / "index.rst", "\n".join(parts))


_SCENE_SCRIPT = '''r"""
{title}
{underline}

{description}

The scene file, ``examples/scenes/{name}.toml``:

.. code-block:: toml

{toml}
"""

# sphinx_gallery_start_ignore
import os
import tempfile

os.chdir({root!r})
out = tempfile.mkdtemp()
# sphinx_gallery_end_ignore
from hovering import pipeline
from hovering.scenes import format_summary, load_scene

scene = load_scene("examples/scenes/{name}.toml", check_output=False)
# quick=True divides the scene's iterate counts by 50 (the gallery is built on every docs build;
# run without it for the figure at full resolution).
summary = pipeline.run_scene(scene, out=os.path.join(out, "{name}.png"), quick=True, keep_figure=True)
print(format_summary(summary))
'''


def _rst_text(text: str) -> str:
    """Plain text for a reStructuredText paragraph: markup characters of the scene files' comments
    (|HOV|, *, `) read literally."""
    return text.replace("\\", "\\\\").replace("*", r"\*").replace("`", "'").replace("|", r"\|").replace("_", r"\_")


def write_scene_gallery(scenes: Path, where: Path) -> None:
    """One ``scene_<name>.py`` per scene file, its text taken from the file's comments and title."""
    _write(
        where / "README.rst",
        "Scenes\n======\n\nEvery example scene (examples/scenes), the paper's figures among them, run in quick mode.\n",
    )
    for path in sorted(scenes.glob("*.toml")):
        text = path.read_text()
        data = tomllib.loads(text)
        comments = [ln[1:].strip() for ln in text.splitlines() if ln.startswith("#")]
        description = _rst_text(" ".join(c for c in comments if not c.startswith("Run:")))
        title = _rst_text(str(data.get("title", path.stem)))
        body = "\n".join("   " + ln if ln else "" for ln in text.splitlines() if not ln.startswith("#"))
        _write(
            where / f"scene_{path.stem}.py",
            _SCENE_SCRIPT.format(
                title=title,
                underline="=" * len(title),
                description=description,
                name=path.stem,
                toml=body,
                root=str(scenes.parent.parent),
            ),
        )
