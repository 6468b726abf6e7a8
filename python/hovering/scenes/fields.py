"""Scene fields declared once: the key, default, range and choices of a spec's field live in the field.

A spec is a frozen dataclass; each field that a scene file gives is declared with one of the
functions below, which put the field's default where the dataclass keeps it (the only copy) and
what is allowed in the field's metadata (a :class:`Param`)::

    @dataclass(frozen=True, kw_only=True)
    class TangentToriScene(FlowScene):
        n_returns: int = integer(3, lo=1, hi=100)
        n_points: int = integer(400, lo=16, hi=100_000)

One generic reader (:func:`read_values`, :func:`read`) turns a TOML table into such a spec: it
refuses an unknown key and a missing required one (naming the allowed keys), reads each key
present with its field's check (every message names the key, the value and what is allowed:
:mod:`hovering.scenes.values`) and leaves every absent key to the dataclass default. One generic
writer (:func:`write`) turns a spec back into its table (:func:`hovering.scenes.schema.scene_table`).

What no range can say (a nested table read by its own rules, a relation between keys) is a
``custom`` field whose reader is a function beside the spec, or a ``check`` run on the value read
(or on the default, when the key is absent).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import MISSING, dataclass

from . import values as v

__all__ = [
    "PARAM",
    "OMIT",
    "Param",
    "Reading",
    "real",
    "integer",
    "flag",
    "choice",
    "text",
    "color",
    "pair",
    "size",
    "integers",
    "distinct_reals",
    "choice_list",
    "table",
    "custom",
    "declared",
    "keys",
    "read_values",
    "read",
    "write",
]

#: The key of a field's metadata that holds its :class:`Param`.
PARAM = "hovering.scene"

#: What a writer returns for a value that its table does not write.
OMIT = object()


@dataclass(frozen=True)
class Param:
    """How a scene file gives one field (kept in the field's metadata under :data:`PARAM`).

    Attributes
    ----------
    read : callable
        ``read(where, value, reading) -> field value``: checks what the file holds at the key
        (``where`` names it in messages, e.g. ``scene.system.eps``).
    allowed : str
        What is allowed, in words (``"[1, 100]"``, ``"'mean', 'birkhoff'"``), for references.
    required : bool
        The key must be given.
    key : str or None
        The key in the file (default: the field's name).
    in_table : str or None
        The key lies in this sub-table (``h`` in ``[section]``), which holds exactly the keys of
        the fields that name it (all required when the sub-table is given).
    kinds : tuple of str or None
        The kinds whose files have the key (default: every kind of the spec class).
    default_from : str, callable or None
        An absent key takes the value of this field (read before it, here or in an enclosing
        table), or ``default_from(where, reading)``.
    check : callable or None
        ``check(where, value, reading)``: run on the value read, or on the default when the key
        is absent (``value`` then the dataclass default; a check of a given key only looks at
        ``reading.table``).
    write : callable or None
        ``write(value, kind) -> TOML value`` (or :data:`OMIT`) for :func:`write`; default: None
        omitted, tuples as lists, dataclasses with declared fields as tables.
    context : bool
        A key of the file that is no field of the spec: a default for its nested tables (the
        ``[map]`` of a truncated scene), kept in ``reading.context`` (declared in the spec's
        ``_keys``).
    """

    read: Callable
    allowed: str = ""
    required: bool = False
    key: str | None = None
    in_table: str | None = None
    kinds: tuple | None = None
    default_from: str | Callable | None = None
    check: Callable | None = None
    write: Callable | None = None
    context: bool = False

    def applies(self, kind: str | None) -> bool:
        """Whether files of this kind have the key.

        Parameters
        ----------
        kind : str or None
            The kind (None: any).

        Returns
        -------
        bool
        """
        return self.kinds is None or kind is None or kind in self.kinds


class Reading:
    """What a reader sees while it reads one table: the table, the values read so far, the kind.

    Parameters
    ----------
    where : str
        The table's name in messages (``scene``, ``scene.system``, ``scene.panels[1]``).
    table : dict
        The table as the file holds it.
    values : dict, optional
        Values already known (for a scene: ``path``, ``name``, ``kind`` and the kind's ``sets``);
        each field read is added.
    parent : Reading, optional
        The reading of the enclosing table.
    kind : Kind, optional
        The scene's kind (default: the parent's).
    options : dict, optional
        How the scene is read (``check_output``, ``path``; default: the parent's).

    Attributes
    ----------
    context : dict
        The context keys read (:attr:`Param.context`).
    """

    def __init__(self, where: str, table: dict, values=None, parent=None, kind=None, options=None):
        self.where, self.table, self.parent = where, table, parent
        self.values = dict(values or {})
        self.context: dict = {}
        self.kind = kind if kind is not None else (parent.kind if parent is not None else None)
        self.options = options if options is not None else (parent.options if parent is not None else {})

    def get(self, name: str, default=None):
        """A value read here or in an enclosing table (a field, or a context key).

        Parameters
        ----------
        name : str
            The field's or context key's name.
        default : object, optional
            When no enclosing table has it.

        Returns
        -------
        object
        """
        r = self
        while r is not None:
            if name in r.values:
                return r.values[name]
            if name in r.context:
                return r.context[name]
            r = r.parent
        return default


def _field(default, param: Param, factory=None):
    md = {PARAM: param}
    if factory is not None:
        return dataclasses.field(default_factory=factory, metadata=md)
    if default is MISSING:
        return dataclasses.field(metadata=md)
    return dataclasses.field(default=default, metadata=md)


def _range(lo, hi, lo_open=False, hi_open=False) -> str:
    left = "(" if lo_open or lo is None else "["
    right = ")" if hi_open or hi is None else "]"
    return f"{left}{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}{right}"


def _required(default, opts: dict) -> dict:
    # A field without default and without a rule for one is a required key.
    opts.setdefault("required", default is MISSING and opts.get("default_from") is None)
    return opts


def real(default=MISSING, *, lo=None, hi=None, lo_open=False, hi_open=False, **opts):
    """A number (or an expression of numbers, ``pi``, ``OMEGA_G``) in a range.

    Parameters
    ----------
    default : float, optional
        The field's default (absent: the key is required).
    lo, hi : float, optional
        Bounds (None: unbounded).
    lo_open, hi_open : bool, optional
        Whether each bound is excluded.
    **opts
        Further :class:`Param` attributes (``key``, ``kinds``, ``check``, ...).

    Returns
    -------
    dataclasses.Field
    """

    def read(where, value, reading):
        return v.real(where, value, lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open)

    return _field(default, Param(read, _range(lo, hi, lo_open, hi_open), **_required(default, opts)))


def integer(default=MISSING, *, lo=None, hi=None, **opts):
    """An integer in ``[lo, hi]``.

    Parameters
    ----------
    default : int, optional
        The field's default (absent: the key is required).
    lo, hi : int, optional
        Bounds, both included.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """

    def read(where, value, reading):
        return v.integer(where, value, lo, hi)

    return _field(default, Param(read, f"[{lo}, {'inf' if hi is None else hi}]", **_required(default, opts)))


def flag(default=MISSING, **opts):
    """``true`` or ``false``.

    Parameters
    ----------
    default : bool, optional
        The field's default.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """
    return _field(
        default, Param(lambda where, value, reading: v.boolean(where, value), "true, false", **_required(default, opts))
    )


def choice(default=MISSING, choices=(), **opts):
    """One of ``choices``.

    Parameters
    ----------
    default : str, optional
        The field's default.
    choices : sequence of str
        The allowed values, in the order messages list them.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """
    choices = tuple(choices)

    def read(where, value, reading):
        return v.text(where, value, choices)

    return _field(default, Param(read, ", ".join(repr(c) for c in choices), **_required(default, opts)))


def text(default=MISSING, *, limit: int = v.MAX_TEXT, drawn: bool = False, **opts):
    """A non-empty string of at most ``limit`` characters.

    Parameters
    ----------
    default : str, optional
        The field's default.
    limit : int, optional
        Longest string.
    drawn : bool, optional
        The figure shows it (a title, a label): its ``$...$`` math must parse
        (:func:`~hovering.scenes.values.drawn_text`).
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """

    def read(where, value, reading):
        return v.drawn_text(where, value, limit=limit) if drawn else v.text(where, value, limit=limit)

    allowed = f"a string of at most {limit} characters" + (" (math between $ signs must parse)" if drawn else "")
    return _field(default, Param(read, allowed, **_required(default, opts)))


def color(default=None, **opts):
    """A matplotlib colour (a name, ``'C0'``..``'C9'``, ``'#rrggbb'``).

    Parameters
    ----------
    default : str or None, optional
        The field's default.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """
    return _field(
        default,
        Param(lambda where, value, reading: v.color(where, value), "a matplotlib colour", **_required(default, opts)),
    )


def pair(default=None, **opts):
    """Two numbers ``[low, high]``, increasing.

    Parameters
    ----------
    default : tuple of float or None, optional
        The field's default.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """
    return _field(
        default,
        Param(
            lambda where, value, reading: v.pair(where, value), "[low, high], low < high", **_required(default, opts)
        ),
    )


def size(default=None, **opts):
    """A figure size ``[width, height]`` in inches.

    Parameters
    ----------
    default : tuple of float or None, optional
        The field's default.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """
    return _field(
        default,
        Param(
            lambda where, value, reading: v.size(where, value),
            "[width, height], each in [0.5, 60.0]",
            **_required(default, opts),
        ),
    )


def integers(default=MISSING, *, names=(), ranges=(), **opts):
    """A list of integers of fixed length, each in its own range (a grid ``[n_phi, n_K]``).

    Parameters
    ----------
    default : tuple of int, optional
        The field's default.
    names : sequence of str
        The entries' names, for the message (``("n_phi", "n_K")``).
    ranges : sequence of (int, int)
        Each entry's bounds, both included.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """
    names, ranges = tuple(names), tuple(ranges)
    shape = f"[{', '.join(names)}]"

    def read(where, value, reading):
        if not isinstance(value, list) or len(value) != len(names):
            raise ValueError(f"{where} must be {shape}, got {value!r}")
        return tuple(v.integer(f"{where}[{i}]", x, lo, hi) for i, (x, (lo, hi)) in enumerate(zip(value, ranges)))

    allowed = f"{shape}, " + ", ".join(f"{n} in [{lo}, {hi}]" for n, (lo, hi) in zip(names, ranges))
    return _field(default, Param(read, allowed, **_required(default, opts)))


def distinct_reals(default=MISSING, *, lo=None, hi=None, lo_open=False, hi_open=False, **opts):
    """A non-empty list of distinct numbers in a range (the eps values of a sweep).

    Parameters
    ----------
    default : tuple of float, optional
        The field's default.
    lo, hi : float, optional
        Bounds of each value.
    lo_open, hi_open : bool, optional
        Whether each bound is excluded.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """
    bounds = {k: x for k, x in dict(lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open).items() if x not in (None, False)}

    def read(where, value, reading):
        return v.distinct_reals(where, value, **bounds)

    allowed = f"1 to {v.MAX_SERIES_POINTS} distinct numbers in {_range(lo, hi, lo_open, hi_open)}"
    return _field(default, Param(read, allowed, **_required(default, opts)))


def choice_list(default=MISSING, choices=(), **opts):
    """A list of names from ``choices`` (kept in the file's order).

    Parameters
    ----------
    default : tuple of str, optional
        The field's default.
    choices : sequence of str
        The allowed names.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """
    choices = tuple(choices)

    def read(where, value, reading):
        if not isinstance(value, list):
            raise ValueError(f"{where} must be a list from {list(choices)}, got {value!r}")
        return tuple(v.text(where, x, choices) for x in value)

    return _field(default, Param(read, f"a list from {list(choices)}", **_required(default, opts)))


def table(cls, **opts):
    """A nested table read by the generic reader into ``cls`` (whose fields are declared too).

    An absent table is read as an empty one, so that its fields' rules for defaults apply; a spec
    built in code gets ``cls()``.

    Parameters
    ----------
    cls : type
        The table's dataclass.
    **opts
        Further :class:`Param` attributes (``required=True``: the table must be given).

    Returns
    -------
    dataclasses.Field
    """

    def read_table(where, value, reading):
        return read(cls, where, value, reading)

    def from_nothing(where, reading):
        return read(cls, where, {}, reading)

    required = opts.pop("required", False)
    param = Param(
        read_table,
        f"a table ({cls.__name__})",
        required=required,
        default_from=None if required else from_nothing,
        **opts,
    )
    return _field(MISSING, param) if required else _field(MISSING, param, factory=cls)


def custom(default=MISSING, *, read, allowed: str = "", **opts):
    """A field read by its own function (a nested table with its own rules, a list of tables).

    Parameters
    ----------
    default : object, optional
        The field's default.
    read : callable
        ``read(where, value, reading) -> field value``.
    allowed : str, optional
        What is allowed, in words.
    **opts
        Further :class:`Param` attributes.

    Returns
    -------
    dataclasses.Field
    """
    return _field(default, Param(read, allowed, **_required(default, opts)))


# ------------------------------------------------------------------------------------------------
# The generic reader and writer


@dataclass(frozen=True)
class _Declared:
    name: str
    param: Param
    default: object
    owner: type


def declared(cls, kind: str | None = None) -> list:
    """The keys of a spec class (and its context keys), in the order its files list them: each class
    of its hierarchy from the base, its context keys then its own fields.

    Parameters
    ----------
    cls : type
        A dataclass whose fields are declared with this module's functions.
    kind : str, optional
        Only the keys of this kind's files.

    Returns
    -------
    list
        Entries with ``name``, ``param`` (:class:`Param`), ``default`` (the dataclass default, or
        ``MISSING``) and ``owner`` (the class that declares it).
    """
    fields = {f.name: f for f in dataclasses.fields(cls)}
    out = []
    for owner in reversed(cls.__mro__):
        for name, f in (owner.__dict__.get("_keys") or {}).items():
            p = dataclasses.replace(f.metadata[PARAM], context=True)
            if p.applies(kind):
                out.append(_Declared(name, p, f.default, owner))
        for name in owner.__dict__.get("__annotations__", {}):
            f = fields.get(name)
            if f is None or PARAM not in f.metadata or any(d.name == name for d in out):
                continue
            p = f.metadata[PARAM]
            if p.applies(kind):
                out.append(_Declared(name, p, _default_of(f), owner))
    return out


def _default_of(f):
    if f.default is not MISSING:
        return f.default
    if f.default_factory is not MISSING:
        return f.default_factory()
    return MISSING


def keys(cls, kind: str | None = None) -> tuple:
    """The keys a table of ``cls`` may have, in order (a sub-table's name once).

    Parameters
    ----------
    cls : type
        The spec class.
    kind : str, optional
        Only the keys of this kind's files.

    Returns
    -------
    tuple of str
    """
    return tuple(dict.fromkeys(d.param.in_table or d.param.key or d.name for d in declared(cls, kind)))


def read_values(cls, where: str, value, reading: Reading, hook: Callable | None = None) -> dict:
    """Read a table into the values of ``cls``'s fields (absent keys are left to the dataclass).

    Parameters
    ----------
    cls : type
        The spec class.
    where : str
        The table's name in messages.
    value : object
        What the file holds (a table, or a message names it).
    reading : Reading
        Where the values go (``reading.values``; context keys to ``reading.context``).
    hook : callable, optional
        ``hook(where, values)``, run after the fields ``cls`` inherits and before its own (a kind's
        :attr:`~hovering.scenes.registry.Kind.check`).

    Returns
    -------
    dict
        Every field's value (given, or its default) and the values known before.

    Raises
    ------
    ValueError
        For an unknown or missing key, or a bad value: naming it, the value and what is allowed.
    """
    t = v.table(where, value)
    reading.table = t
    kind = reading.kind.name if reading.kind is not None else None
    params = declared(cls, kind)
    allowed = keys(cls, kind)
    required = tuple(dict.fromkeys(d.param.in_table or d.param.key or d.name for d in params if d.param.required))
    v.check_keys(where, t, allowed, required)
    hooked = hook is None
    for d in params:
        if not hooked and d.owner is cls:
            hook(where, reading.values)
            hooked = True
        if d.name in reading.values and not d.param.context:
            continue  # known before reading (a scene's path, name, kind and what its kind sets)
        p, key = d.param, d.param.key or d.name
        sub, at = t, f"{where}.{key}"
        if p.in_table is not None:
            sub = {}
            if p.in_table in t:
                st = v.table(f"{where}.{p.in_table}", t[p.in_table])
                inside = tuple(x.param.key or x.name for x in params if x.param.in_table == p.in_table)
                v.check_keys(f"{where}.{p.in_table}", st, inside, inside)
                sub = st
            at = f"{where}.{p.in_table}.{key}"
        if key in sub:
            value = p.read(at, sub[key], reading)
        elif isinstance(p.default_from, str):
            value = reading.get(p.default_from, MISSING)
        elif p.default_from is not None:
            value = p.default_from(at, reading)
        else:
            value = d.default
        if p.check is not None and value is not MISSING:
            p.check(at, value, reading)
        if value is MISSING:
            continue
        # Defaults are stored too (the dataclass's own), so that later checks see every value.
        (reading.context if p.context else reading.values)[d.name] = value
    if not hooked:
        hook(where, reading.values)
    return reading.values


def read(cls, where: str, value, parent: Reading | None = None, **known):
    """Read a nested table into an instance of ``cls``.

    Parameters
    ----------
    cls : type
        Its dataclass.
    where : str
        The table's name in messages.
    value : object
        What the file holds.
    parent : Reading, optional
        The reading of the enclosing table (its values are seen by ``default_from``).
    **known
        Field values given by the enclosing table (not keys of this one).

    Returns
    -------
    object
        ``cls(**values)``.
    """
    return cls(**read_values(cls, where, value, Reading(where, {}, known, parent=parent)))


def write(obj, kind=None) -> dict:
    """The table that :func:`read_values` reads as ``obj`` (every declared field, defaults included).

    Parameters
    ----------
    obj : object
        A dataclass instance whose fields are declared.
    kind : Kind, optional
        The scene's kind (only its keys are written; a field's writer may ask for it).

    Returns
    -------
    dict
        Plain TOML values: None omitted, tuples as lists, declared dataclasses as tables.
    """
    out: dict = {}
    for d in declared(type(obj), kind.name if kind is not None else None):
        if d.param.context:
            continue  # a default for nested tables, which are written resolved
        value = getattr(obj, d.name)
        value = d.param.write(value, kind) if d.param.write is not None else _plain(value, kind)
        if value is OMIT or value is None:
            continue
        key = d.param.key or d.name
        if d.param.in_table is not None:
            out.setdefault(d.param.in_table, {})[key] = value
        else:
            out[key] = value
    return out


def _plain(value, kind):
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return write(value, kind)
    if isinstance(value, tuple):
        return [_plain(x, kind) for x in value]
    return value
