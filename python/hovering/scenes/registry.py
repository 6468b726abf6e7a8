"""The registry of scene kinds: each kind is one :class:`Kind`, declared in its own module.

A kind's module (``hovering/scenes/kinds/<kind>.py``, or any module of another package) declares
its spec (a frozen dataclass whose fields carry their default, range and choices:
:mod:`hovering.scenes.fields`), its result class, its compute function, the numbers its summary
shows and the lines its report prints, and registers them with ``KIND = register(Kind(...))``.
Everything else reads the registry: the scene reader (which keys a file of that kind may have),
``compute``, ``summarize``, ``format_summary``, ``figure_inches``, the sweep plan. Its figure is
drawn by ``hovering/plot/kinds/<kind>.py`` (the drawing side registers it there: scenes never
import plot).

The kinds of this package are found, not listed: :mod:`hovering.scenes.kinds` imports every module
in its folder. A kind from elsewhere is registered by importing its module.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field

__all__ = ["Kind", "FAMILIES", "register", "unregister", "get", "names"]

#: The families of kinds, in the order :func:`names` lists them: scenes of the truncated map, then
#: scenes of the physical flow.
FAMILIES = ("truncated", "flow")


@dataclass(frozen=True)
class Kind:
    """One scene kind: everything about it that is not its figure.

    Attributes
    ----------
    name : str
        The ``kind`` of its scene files.
    spec : type
        Its spec: a frozen dataclass deriving from :class:`~hovering.scenes.base.SceneSpec` whose
        fields declare their keys (:mod:`hovering.scenes.fields`).
    result : type
        Its result: a dataclass deriving from :class:`~hovering.scenes.base.SceneResult`.
    compute : callable
        ``compute(spec, ctx) -> result`` (``ctx``: :class:`~hovering.scenes.base.Context`).
    summarize : callable
        ``summarize(result) -> dict``: the numbers its summary shows, beyond what every summary has.
    report : callable
        ``report(summary) -> list of str``: the lines the command line prints for them.
    family : {"truncated", "flow"}
        Which model it is about.
    doc : str
        One line: what its figure shows.
    figsize : tuple of float or None
        Its figure's size in inches when the scene gives none (None: from the panels' layout).
    records : tuple
        Flow kinds: ``(allowed, required)`` names of ``[outputs] record`` (what its figure is drawn
        from is required).
    sets : dict
        Spec fields the kind fixes (not keys of its files), e.g. a portrait draws no leading curve.
    check : callable or None
        ``check(where, values)``: relations between its shared tables that the kind needs (e.g. a
        wall kind's energy above the corner's), run after those tables are read and before the
        kind's own keys, so that a message names the table at fault.
    scene_map : callable or None
        ``scene_map(spec)``: the map the scene is about (the explorer, ``hovering accuracy``).
    plan : callable or None
        Sweep kinds: ``plan(spec, quick) -> list of points`` (:mod:`hovering.scenes.plan`); such a
        scene checkpoints its points (``<output>.sweep.jsonl``).
    quick_floor : tuple of int
        Sweep kinds: the fewest ``(n_steps, samples)`` of a ``--quick`` run.
    """

    name: str
    spec: type
    result: type
    compute: Callable
    summarize: Callable
    report: Callable
    family: str = "flow"
    doc: str = ""
    figsize: tuple | None = None
    records: tuple = ((), ())
    sets: dict = field(default_factory=dict)
    check: Callable | None = None
    scene_map: Callable | None = None
    plan: Callable | None = None
    quick_floor: tuple = (100, 400)

    @property
    def sweep(self) -> bool:
        """Whether its scenes are sweeps (a plan of points, checkpointed)."""
        return self.plan is not None


_KINDS: dict = {}


def register(kind: Kind) -> Kind:
    """Add a kind to the registry (its module calls this once: ``KIND = register(Kind(...))``).

    Parameters
    ----------
    kind : Kind
        The declaration.

    Returns
    -------
    Kind
        ``kind``.

    Raises
    ------
    ValueError
        For a name another module already registered, a family not in :data:`FAMILIES`, or a
        spec or result that is not a dataclass.
    """
    if not isinstance(kind, Kind):
        raise ValueError(f"register takes a Kind, got {type(kind).__name__}")
    if not kind.name.isidentifier():
        raise ValueError(f"a kind's name is an identifier (it names a scene file's kind), got {kind.name!r}")
    if kind.family not in FAMILIES:
        raise ValueError(f"kind {kind.name!r}: family = {kind.family!r}; allowed: {', '.join(FAMILIES)}")
    for what in ("spec", "result"):
        if not dataclasses.is_dataclass(getattr(kind, what)):
            raise ValueError(f"kind {kind.name!r}: its {what} must be a dataclass, got {getattr(kind, what)!r}")
    old = _KINDS.get(kind.name)
    # A module imported again (importlib.reload) replaces its own kinds; another module may not.
    if old is not None and old.spec.__module__ != kind.spec.__module__:
        raise ValueError(f"kind {kind.name!r} is already registered by {old.spec.__module__}")
    _KINDS[kind.name] = kind
    # The result answers its own summary: code below the kinds (SceneResult.summary and save, in
    # scenes.base) dispatches on the result's class rather than looking its kind up in this table,
    # which only the modules above the kinds read (compute, schema, report, plan).
    kind.result._summarize_kind = staticmethod(kind.summarize)
    return kind


def unregister(name: str) -> None:
    """Remove a kind from the registry (a test's temporary kind).

    Parameters
    ----------
    name : str
        The kind's name (absent: nothing happens).
    """
    _KINDS.pop(name, None)


def get(name: str) -> Kind:
    """The registered kind of this name.

    Parameters
    ----------
    name : str
        A scene file's ``kind``.

    Returns
    -------
    Kind

    Raises
    ------
    ValueError
        For a name no module registered, naming the kinds that are.
    """
    kind = _KINDS.get(name)
    if kind is None:
        raise ValueError(f"no scene kind {name!r}; allowed: {', '.join(repr(k) for k in names())}")
    return kind


def names(family: str | None = None) -> tuple:
    """The registered kinds' names: the truncated map's, then the flow's, each alphabetically (an
    order that does not depend on which module was imported first).

    Parameters
    ----------
    family : {"truncated", "flow"}, optional
        Only this family's.

    Returns
    -------
    tuple of str
    """
    fams = FAMILIES if family is None else (family,)
    return tuple(k for f in fams for k in sorted(_KINDS) if _KINDS[k].family == f)
