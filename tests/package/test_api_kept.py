"""The API stays, or warns: every public name of 0.2.0 (each module's ``__all__`` at df278ce, the
commit before the restructuring; tests/data/api-0.2.0.json) still resolves under its old module path,
either silently (it did not move) or with one DeprecationWarning that names its replacement and the
release that removes it."""

from __future__ import annotations

import importlib
import json
import re
import warnings
from pathlib import Path

import pytest

import hovering

API = json.loads((Path(__file__).parents[1] / "data" / "api-0.2.0.json").read_text())["public"]
NAMES = [(mod, name) for mod, names in sorted(API.items()) for name in names]
MESSAGE = re.compile(
    r"^(hovering[\w.]*) is deprecated and will be removed in hovering (\d+\.\d+\.\d+); use (.+) instead$"
)


def test_the_snapshot_is_the_whole_public_api():
    # 69 names at the top level and 352 across the public modules of 0.2.0.
    assert len(API["hovering"]) == 69 and len(NAMES) == 352


@pytest.mark.parametrize("mod,name", NAMES, ids=[f"{m}.{n}" for m, n in NAMES])
def test_every_public_name_of_0_2_0_still_resolves_or_warns(mod, name):
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        module = importlib.import_module(mod)
        value = getattr(module, name)
    deprecations = [x for x in w if issubclass(x.category, DeprecationWarning)]
    assert [x for x in w if not issubclass(x.category, DeprecationWarning)] == []
    if deprecations:
        assert len(deprecations) == 1
        m = MESSAGE.match(str(deprecations[0].message))
        assert m, str(deprecations[0].message)
        assert m.group(2) == hovering._deprecated.REMOVED_IN
        assert m.group(1) == f"{mod}.{name}"
        # the replacement it names exists and is the same object
        new = m.group(3)
        path, _, attr = new.rpartition(".")
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert getattr(importlib.import_module(path), attr) is value
