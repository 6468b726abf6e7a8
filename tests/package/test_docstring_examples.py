"""The Examples sections of the public API's docstrings run as written (doctest), and the names a
user calls first keep one.

Collected: the docstring of every public name (``hovering.__all__``, and the ``__all__`` of the
public subpackages in it, e.g. ``hovering.analysis.TransitResult``), of its methods and properties
(those defined in the package, inherited ones included: ``TruncatedMap.iterate`` lives in a mixin
of the compiled class), and of the public modules themselves. Each docstring with ``>>>`` lines is
one test, run in a fresh namespace with NORMALIZE_WHITESPACE and ELLIPSIS: a reader copies an
example into an empty session.

The examples print only what does not depend on the last digits of a floating-point result (a
SIMD width or a libm rounds sin differently, and numpy 1.x and 2.x print scalars differently):
shapes, counts, booleans and numbers formatted to a few digits.
"""

from __future__ import annotations

import doctest
import inspect
import os
import re
import types

import pytest

import hovering

#: The names a user calls first: each keeps an Examples section (a test fails when one is removed).
REQUIRED = (
    "TruncatedMap",
    "TruncatedMap.iterate",
    "FlowMap",
    "FlowMap.iterate",
    "FlowMap.returns",
    "StepSystem",
    "Section",
    "Section.return_map",
    "hovering_area",
    "critical_curve",
    "impact_zone",
    "transit",
    "barrier_scan",
    "compare_hovering",
    # what they return
    "IterateResult",
    "ReturnMapResult",
    "FlowSteps",
    "HoveringArea",
    "HoveringComponents",
    "CriticalCurve",
    "ImpactZone",
    "analysis.TransitResult",
    "BarrierScan",
    "analysis.Layer",
    "HoveringComparison",
    "ModelVerdicts",
    "Theory",
)

FLAGS = doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS

# Old module paths that warn when used (hovering._deprecated): no documentation of their own.
_SKIP_MODULES = {m.rpartition(".")[2] for m in hovering._deprecated.OLD_MODULES}


def _own(obj) -> bool:
    """Whether obj is defined in the package (not numpy's, not the compiled core's)."""
    mod = getattr(obj, "__module__", None) or ""
    return mod.startswith("hovering") and not mod.startswith("hovering._core")


def _members(cls) -> dict:
    """name -> function/property of cls and its bases defined in the package (nearest first)."""
    out: dict = {}
    for base in cls.__mro__:
        if not _own(base):
            continue
        for name, value in vars(base).items():
            if name in out or (name.startswith("_") and name != "__call__"):
                continue
            if isinstance(value, (staticmethod, classmethod)):
                value = value.__func__
            if isinstance(value, (types.FunctionType, property)):
                out[name] = value
    return out


def _public() -> dict:
    """Qualified name (relative to ``hovering``) -> object of every public name and module."""
    out: dict = {"hovering": hovering}
    for name in hovering.__all__:
        if name.startswith("__") or name in _SKIP_MODULES:
            continue
        obj = getattr(hovering, name)
        out[name] = obj
        if isinstance(obj, types.ModuleType):
            for sub in getattr(obj, "__all__", []):
                value = getattr(obj, sub)
                if sub.startswith("__") or isinstance(value, types.ModuleType) or sub in hovering.__all__:
                    continue
                out[f"{name}.{sub}"] = value
    return out


def _docstrings() -> dict:
    """Qualified name -> (docstring, file, line) of every public object and method with a docstring."""
    out: dict = {}
    seen: set = set()

    def add(name, obj):
        doc = obj.__doc__ if isinstance(obj, property) else inspect.getdoc(obj)
        target = obj.fget if isinstance(obj, property) else obj
        if not doc or id(target) in seen:
            return
        seen.add(id(target))
        try:
            path, line = os.path.realpath(inspect.getsourcefile(target)), inspect.getsourcelines(target)[1]
        except (TypeError, OSError):
            path, line = name, 0
        out[name] = (inspect.cleandoc(doc), path, line)

    # The names a user calls first before the others: a method two classes share (TruncatedMap's and
    # TruncatedFamily's iterate) is collected once, under the first name, whatever __all__'s order.
    public = _public()
    order = sorted(public, key=lambda n: (n not in REQUIRED, REQUIRED.index(n) if n in REQUIRED else 0))
    for name, obj in ((n, public[n]) for n in order):
        if isinstance(obj, types.ModuleType):
            add(name, obj)
        elif inspect.isclass(obj):
            add(name, obj)
            for member, value in _members(obj).items():
                add(f"{name}.{member}", value)
        elif callable(obj) and _own(obj):
            add(name, obj)
    return out


DOCSTRINGS = _docstrings()
PARSER = doctest.DocTestParser()
WITH_EXAMPLES = sorted(n for n, (doc, _, _) in DOCSTRINGS.items() if PARSER.get_examples(doc))


@pytest.mark.parametrize("name", WITH_EXAMPLES)
def test_docstring_examples_run(name):
    doc, path, line = DOCSTRINGS[name]
    test = PARSER.get_doctest(doc, {}, name, path, line)
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    report: list[str] = []
    runner.run(test, out=report.append, clear_globs=True)
    assert runner.failures == 0, f"{name}'s examples failed:\n" + "".join(report)


def _resolve(name: str):
    obj = hovering
    for part in name.split("."):
        obj = getattr(obj, part)
    return obj


@pytest.mark.parametrize("name", REQUIRED)
def test_first_names_have_an_examples_section(name):
    obj = _resolve(name)
    doc = inspect.getdoc(obj) or ""
    m = re.search(r"^Examples\n-{8}\n(.*)", doc, flags=re.M | re.S)
    assert m, f"hovering.{name} has no numpydoc 'Examples' section"
    assert ">>>" in m.group(1), f"hovering.{name}'s Examples section has no >>> example"
    assert name in DOCSTRINGS and name in WITH_EXAMPLES, f"hovering.{name}'s examples are not collected"


def test_the_collection_reaches_methods_and_subpackages():
    # The collector itself: a mixin's method, a property, a subpackage-only class.
    assert {"TruncatedMap.iterate", "FlowMap.iterate", "analysis.TransitResult", "IterateResult.n_orbits"} <= set(
        DOCSTRINGS
    )
