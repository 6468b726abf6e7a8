"""Sphinx configuration of the hovering documentation (built by ``bash scripts/docs.sh``).

The API pages are generated from ``hovering.__all__`` and the subpackages' ``__all__``, grouped by
the topics of ``_generate.API_GROUPS`` (so every public name has a page in one topic,
tests/package/test_docs.py checks it), and the C++ API page from the public headers' ``///``
comments; the gallery is generated from the scene files in examples/scenes (one page per scene,
run in quick mode at build time) and the scripts in examples/gallery.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import hovering

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

from _generate import write_api_pages, write_scene_gallery  # noqa: E402

project = "hovering"
author = "the hovering developers"
copyright = "2026, the hovering developers"
release = version = hovering.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "sphinx.ext.intersphinx",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "internals", "**/*.png", "README.md", "_scene_gallery", "_templates"]
templates_path = ["_templates"]
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

html_theme = "furo"
html_title = f"hovering {release}"
html_static_path: list = []

# Links into the projects the API takes and returns. Sphinx reports an inventory it cannot fetch
# with a warning that has no type (suppress_warnings cannot name it), which -W turns into a failed
# build; so the inventories are probed first, all at once, and only those that answer are used: a
# build without network passes, without these links. HOVERING_DOCS_INTERSPHINX=1 uses them all
# unprobed (an unreachable one then fails the build), =0 none.
INTERSPHINX = {
    "numpy": "https://numpy.org/doc/stable/",
    "scipy": "https://docs.scipy.org/doc/scipy/",
    "xarray": "https://docs.xarray.dev/en/stable/",
    "matplotlib": "https://matplotlib.org/stable/",
}
intersphinx_timeout = 10


def _reachable(urls: dict, timeout: float = 5.0) -> dict:
    """The entries of ``urls`` whose ``objects.inv`` answers (any HTTP status: a server is there)."""
    import urllib.error
    import urllib.request
    from concurrent.futures import ThreadPoolExecutor

    def answers(url: str) -> bool:
        try:
            with urllib.request.urlopen(urllib.request.Request(url + "objects.inv", method="HEAD"), timeout=timeout):
                pass
        except urllib.error.HTTPError:
            return True
        except (OSError, ValueError):  # no route, no name, refused, timed out
            return False
        return True

    with ThreadPoolExecutor(len(urls)) as pool:
        ok = dict(zip(urls, pool.map(answers, urls.values())))
    return {name: url for name, url in urls.items() if ok[name]}


_mode = os.environ.get("HOVERING_DOCS_INTERSPHINX", "auto")
if _mode == "0":
    _linked: dict = {}
elif _mode == "1":
    _linked = dict(INTERSPHINX)
else:
    _linked = _reachable(INTERSPHINX)
    if len(_linked) < len(INTERSPHINX):
        print(f"[docs] no links into {sorted(set(INTERSPHINX) - set(_linked))}: their inventories did not answer")
intersphinx_mapping = {name: (url, None) for name, url in _linked.items()}

autosummary_generate = True
autodoc_default_options = {"members": True, "inherited-members": False, "show-inheritance": True}
autodoc_typehints = "none"  # the numpydoc sections say the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False


def _literal_pipes(app, what, name, obj, options, lines):
    """Docstrings write |HOV|, |J_R| and |x| as mathematics: escape the bars outside inline
    literals, or reStructuredText reads them as substitution references."""
    for i, line in enumerate(lines):
        parts = line.split("``")
        lines[i] = "``".join(p.replace("|", r"\|") if k % 2 == 0 else p for k, p in enumerate(parts))


def setup(app):
    app.connect("autodoc-process-docstring", _literal_pipes, priority=400)


write_api_pages(HERE / "api")
write_scene_gallery(ROOT / "examples" / "scenes", HERE / "_scene_gallery")

sphinx_gallery_conf = {
    "examples_dirs": [str(HERE / "_scene_gallery"), str(ROOT / "examples" / "gallery")],
    "gallery_dirs": ["gallery/scenes", "gallery/examples"],
    "filename_pattern": r"/(plot_|scene_)",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "abort_on_example_error": True,
}
os.environ.setdefault("MPLBACKEND", "Agg")
