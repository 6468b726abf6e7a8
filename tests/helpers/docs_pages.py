"""The documentation's Python code, as the tests run it: README.md and the user guide's pages."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
GUIDE = ROOT / "docs" / "guide"
#: The user guide in reading order (the toctree of docs/guide/index.md, which a test compares with
#: this): their Python blocks run in this order, in one namespace, as a reader would run them.
PAGES = (
    "truncated-map",
    "outcomes",
    "transport",
    "analyses",
    "sweeps",
    "scenes",
    "flow",
    "normal",
    "tangent",
    "custom-potentials",
    "errata",
    "accuracy",
)


def python_blocks(path: Path) -> list[str]:
    """The fenced ```python blocks of one Markdown file, in order."""
    return re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)


def guide_blocks() -> list[tuple[Path, str]]:
    """(page, code) of every Python block of the user guide, in reading order."""
    return [(GUIDE / f"{p}.md", code) for p in PAGES for code in python_blocks(GUIDE / f"{p}.md")]
