#!/usr/bin/env python3
"""Print pip constraints that pin every dependency pyproject.toml declares (build, run and the
extras asked for, and the extras those name, as ``hovering[pandas]``) to its declared minimum:
``numpy>=1.23.2`` becomes ``numpy==1.23.2``.

``scripts/test.sh --oldest`` installs with these constraints (``PIP_CONSTRAINT``, which pip also
applies inside the isolated build environment), so the suite runs against the floors the package
promises. pyproject.toml stays the one place the floors are written; this only reads them.

Usage: floors.py [EXTRA ...] (default: test). Exit status 2 if a requirement has no ``>=`` floor.
       floors.py --requires build|EXTRA   the requirements as declared (one per line), for scripts
       that install them without building the package (scripts/setup.sh, scripts/wheel.sh).
"""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# name[extras] >= version (other specifiers after a comma are allowed and ignored here)
REQ = re.compile(r"^\s*([A-Za-z0-9_.-]+)(\[[^\]]*\])?\s*>=\s*([0-9][0-9A-Za-z.]*)\s*(,.*)?$")


def floors(extras: list[str]) -> list[str]:
    """Constraint lines ``name==floor`` for the build requirements, the dependencies and the
    requirements of ``extras``, in that order, each name once."""
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    reqs = list(meta["build-system"]["requires"]) + list(meta["project"]["dependencies"])
    optional = meta["project"].get("optional-dependencies", {})
    name = meta["project"]["name"]
    done: set[str] = set()

    def add(extra):
        if extra in done:
            return
        done.add(extra)
        if extra not in optional:
            raise SystemExit(f"floors.py: no extra {extra!r} in pyproject.toml (have: {', '.join(optional)})")
        for r in optional[extra]:
            own = re.match(rf"^\s*{re.escape(name)}\[([^\]]*)\]\s*$", r)
            if own:  # an extra made of others ("hovering[pandas]"): their requirements
                for e in own.group(1).split(","):
                    add(e.strip())
            else:
                reqs.append(r)

    for extra in extras:
        add(extra)
    out, seen = [], set()
    for r in reqs:
        m = REQ.match(r)
        if m is None:
            print(f"floors.py: requirement {r!r} declares no '>=' minimum", file=sys.stderr)
            raise SystemExit(2)
        name = m.group(1).lower().replace("_", "-")
        if name not in seen:
            seen.add(name)
            out.append(f"{name}=={m.group(3)}")
        if name == "dask" and m.group(2) and "distributed" in m.group(2) and "distributed" not in seen:
            # dask[distributed] pins distributed to dask's own version
            seen.add("distributed")
            out.append(f"distributed=={m.group(3)}")
    return out


def requires(what: str) -> list[str]:
    """The requirement strings pyproject.toml declares for ``what``: ``"build"`` (the build system's)
    or the name of an extra (its own lines only, not the extras it names)."""
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    if what == "build":
        return list(meta["build-system"]["requires"])
    optional = meta["project"].get("optional-dependencies", {})
    if what not in optional:
        raise SystemExit(f"floors.py: no extra {what!r} in pyproject.toml (have: build, {', '.join(optional)})")
    return list(optional[what])


if __name__ == "__main__":
    if sys.argv[1:2] == ["--requires"]:
        if len(sys.argv) != 3:
            raise SystemExit("floors.py --requires takes one name: build or an extra")
        print("\n".join(requires(sys.argv[2])))
    else:
        print("\n".join(floors(sys.argv[1:] or ["test"])))
