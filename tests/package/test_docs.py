"""The documentation site's generated pages (docs/_generate.py): every public name has an API
entry, every example scene a gallery page. The build itself (Sphinx, warnings as errors) runs in
`bash scripts/docs.sh`, which CI calls."""

from __future__ import annotations

import importlib
import re
import sys
import types
from pathlib import Path

import hovering

DOCS = Path(__file__).resolve().parents[2] / "docs"
sys.path.insert(0, str(DOCS))
import _generate  # noqa: E402

sys.path.remove(str(DOCS))


def _entries(index: str) -> set[str]:
    """module.name of every autosummary entry of the API index."""
    out, module = set(), None
    for line in index.splitlines():
        m = re.match(r"\.\. currentmodule:: (\S+)", line)
        if m:
            module = m.group(1)
        elif re.match(r"   [A-Za-z_]\w*$", line):
            out.add(f"{module}.{line.strip()}")
    return out


def test_every_public_name_has_an_api_entry(tmp_path):
    _generate.write_api_pages(tmp_path)
    entries = _entries((tmp_path / "index.rst").read_text())
    top = {
        n for n in hovering.__all__ if not n.startswith("__") and not isinstance(getattr(hovering, n), types.ModuleType)
    }
    assert {f"hovering.{n}" for n in top} <= entries
    for sub in _generate.SUBPACKAGES:
        mod = importlib.import_module(sub)
        for n in getattr(mod, "__all__", []):
            obj = getattr(mod, n)
            if n.startswith("__") or isinstance(obj, types.ModuleType):
                continue
            assert f"hovering.{n}" in entries or f"{sub}.{n}" in entries, f"{sub}.{n} has no API entry"
    # and nothing listed that does not exist (a stale entry would be a build error)
    for e in entries:
        module, _, name = e.rpartition(".")
        assert hasattr(importlib.import_module(module), name), e


def test_every_example_scene_has_a_gallery_page(tmp_path):
    scenes = DOCS.parent / "examples" / "scenes"
    _generate.write_scene_gallery(scenes, tmp_path)
    pages = {p.stem.removeprefix("scene_") for p in tmp_path.glob("scene_*.py")}
    assert pages == {p.stem for p in scenes.glob("*.toml")}
    for p in tmp_path.glob("scene_*.py"):
        compile(p.read_text(), str(p), "exec")  # valid Python, its docstring included
