"""Pages the docs build writes before Sphinx reads the sources: the API index (from ``__all__``,
grouped by topic), the C++ API page (from the public headers' ``///`` comments) and one gallery
script per scene file (each runs its scene in quick mode)."""

from __future__ import annotations

import dataclasses
import importlib
import re
import tomllib
import types
from dataclasses import dataclass
from pathlib import Path

import hovering

#: Subpackages with an API page of their own, in reading order (their names not exported at the top).
SUBPACKAGES = (
    "hovering.truncated",
    "hovering.flow",
    "hovering.normal",
    "hovering.analysis",
    "hovering.dynamics",
    "hovering.diagnostics",
    "hovering.parallel",
    "hovering.scenes",
    "hovering.plot",
    "hovering.pipeline",
    "hovering.paper",
)


#: The API index's topics, in reading order: (title, one sentence, names). A name is one of
#: ``hovering.__all__``, or ``sub.Name`` for a name only a subpackage exports (it then leaves that
#: subpackage's section). Every top-level name lies in exactly one group; a new public name must be
#: placed here, or the build stops (tests/package/test_docs.py says which).
API_GROUPS = (
    (
        "Truncated maps",
        "The paper's truncated map F_eps and the general family F_{eps1,eps2}, iterated in C++.",
        ("TruncatedMap", "TruncatedFamily", "ReturnMap"),
    ),
    (
        "Leading-order theory",
        "The closed-form predictions of the paper: the hovering set's area, the critical curve, the lines L1 and L2.",
        (
            "theory",
            "Theory",
            "OMEGA_G",
            "L1",
            "L2",
            "k_eps1",
            "k_eps2",
            "rho1",
            "rho2",
            "K_crit",
            "rho_crit",
            "hovering_area_theory",
            "golden_family",
        ),
    ),
    (
        "Physical system and flow",
        "Potentials, the oscillators-step system, its onset parameters and the section Sigma_h with its return map.",
        (
            "StepSystem",
            "Potential",
            "Harmonic",
            "Tan",
            "Numerical",
            "CustomPotential",
            "check_potential",
            "Bilinear",
            "Polynomial",
            "onset_parameters",
            "Section",
        ),
    ),
    (
        "The flow as a map",
        "Normal coordinates (phi, K), the flow's return map iterated like the models, and the models built from it.",
        (
            "FlowMap",
            "tangential_curve",
            "to_normal",
            "from_normal",
            "forcing_function",
            "forcing_coefficients",
            "corner_curves",
            "truncated_from_flow",
            "compare_maps",
        ),
    ),
    (
        "Analyses",
        "Written once for every map: rotation numbers, the hovering set, the critical curve, orbit classes.",
        (
            "hovering_area",
            "critical_curve",
            "compare_hovering",
            "rotation_number",
            "birkhoff_average",
            "regularity",
            "classify_orbits",
            "cone_crossing",
            "converse_kam",
        ),
    ),
    (
        "Tangent dynamics",
        "Jacobians of a return and what they find: periodic orbits with their residues and stability, Lyapunov exponents, invariant manifolds and their lobes, continuation.",
        (
            "periodic_orbit",
            "periodic_orbits",
            "PeriodicOrbit",
            "PeriodicOrbits",
            "lyapunov",
            "LyapunovResult",
            "ftle_field",
            "FTLEField",
            "manifold",
            "Manifold",
            "lobes",
            "Lobes",
            "continue_orbit",
            "Branch",
        ),
    ),
    (
        "Transport across the impact zone",
        "The zone between its floor and ceiling, transits across it, barriers, and the curves that stop an orbit.",
        ("impact_zone", "impact_zone_floor", "transit", "barrier_scan", "Curve", "Above", "Below"),
    ),
    (
        "Results",
        "What the computations return: each holds its numbers, a summary repr, and saves to NPZ.",
        (
            "IterateResult",
            "StepJacobian",
            "ReturnMapResult",
            "FlowSteps",
            "OnsetParameters",
            "TangentialCurve",
            "CornerCurves",
            "MapComparison",
            "HoveringArea",
            "HoveringComponents",
            "HoveringComparison",
            "ModelVerdicts",
            "CriticalCurve",
            "OrbitClasses",
            "ConeCrossing",
            "ImpactZone",
            "BarrierScan",
            "WorkPrecision",
            "analysis.TransitResult",
            "analysis.Layer",
        ),
    ),
    (
        "Outcomes and labels",
        "Per-orbit statuses, the regions of a return, the walls of a system.",
        ("Status", "FlowStatus", "Region", "Geometry", "TrajectoryPoint", "region_mask", "wrap"),
    ),
    (
        "Utilities",
        "Accuracy with its cost and accuracy targets, files, provenance, the SIMD kernel, the interactive explorer.",
        (
            "work_precision",
            "accurate_flow_map",
            "save",
            "load",
            "show_versions",
            "explore",
            "simd_width",
            "simd_is_avx2",
        ),
    ),
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


def group_entries() -> list[tuple[str, str, list[tuple[str, str]]]]:
    """API_GROUPS resolved: ``(title, sentence, [(module, name), ...])``.

    Raises
    ------
    ValueError
        If a top-level public name is in no group or in two, or a group names something that is
        not public (the message names them and this file).
    """
    top = public_names(hovering)
    out, placed = [], []
    for title, sentence, names in API_GROUPS:
        entries = []
        for n in names:
            sub, _, name = n.rpartition(".")
            module = f"hovering.{sub}" if sub else "hovering"
            if (sub and name not in public_names(importlib.import_module(module))) or (not sub and n not in top):
                raise ValueError(f"docs/_generate.py API_GROUPS: {n!r} ({title}) is not a public name of {module}")
            entries.append((module, name))
            placed.append(n)
        out.append((title, sentence, entries))
    twice = sorted({n for n in placed if placed.count(n) > 1})
    missing = [n for n in top if n not in placed]
    if twice or missing:
        raise ValueError(
            "docs/_generate.py API_GROUPS must hold every public name of hovering exactly once: "
            f"in no group {missing}, in two {twice}"
        )
    return out


def write_api_pages(where: Path) -> None:
    """``api/index.rst``: the top-level names by topic (:data:`API_GROUPS`), then each subpackage's
    own names; and ``api/cpp.md``, the C++ API (:func:`write_cpp_page`)."""
    parts = [
        "API reference",
        "=============",
        "",
        "Every public name of ``hovering`` (``hovering.__all__``) by topic, then each subpackage's",
        "names that are not exported at the top level. Generated from the docstrings; the C++",
        "library's public headers are on :doc:`their own page <cpp>`.",
        "",
    ]
    grouped = set()
    for title, sentence, entries in group_entries():
        parts += [title, "-" * len(title), "", sentence, ""]
        modules = list(dict.fromkeys(m for m, _ in entries))  # in order of first appearance
        for module in modules:
            names = [n for m, n in entries if m == module]
            parts.append(_autosummary(module, names))
            grouped |= {f"{module}.{n}" for n in names}
    parts += ["Subpackages", "-----------", ""]
    top = set(public_names(hovering))
    for sub in SUBPACKAGES:
        mod = importlib.import_module(sub)
        own = [n for n in public_names(mod) if n not in top and f"{sub}.{n}" not in grouped]
        if not own:
            continue
        title = f"``{sub}``"
        first = (mod.__doc__ or "").strip().split("\n\n")[0].replace("\n", " ")
        parts += [title, "~" * len(title), "", first, "", _autosummary(sub, sorted(own, key=str.lower))]
    _write(where / "index.rst", "\n".join(parts))
    write_cpp_page(where / "cpp.md")


#: The C++ library's public headers: what ``cmake --install`` installs (CMakeLists.txt:
#: ``install(DIRECTORY cpp/include/hovering ... PATTERN sweep EXCLUDE)``, the sweep executable's
#: headers left out) and the version header CMake generates from its template.
CPP_INCLUDE = Path(__file__).resolve().parents[1] / "cpp" / "include"
CPP_EXCLUDED = ("sweep",)
CPP_GENERATED = {"hovering/version.hpp": CPP_INCLUDE.parent / "cmake" / "version.hpp.in"}


@dataclass(frozen=True)
class CppDeclaration:
    """One declaration of a public header, as :func:`cpp_declarations` reads it.

    Attributes
    ----------
    header : str
        Its header as a consumer includes it (``hovering/curve.hpp``).
    line : int
        Line of its first token (1-based).
    scope : str
        The classes it is a member of (``Curve``; ``""`` at namespace scope).
    kind : str
        ``"class"`` (also struct), ``"enum"``, ``"enumerator"``, ``"function"`` or ``"variable"``
        (also a constant or a type alias).
    text : str
        The declaration without its body or initializer, whitespace collapsed.
    doc : str
        Its ``///`` comment (the lines before it and a ``///<`` after it), joined; ``""`` if none.
    """

    header: str
    line: int
    scope: str
    kind: str
    text: str
    doc: str


def public_headers() -> dict[str, Path]:
    """``{include path: file}`` of every installed public header, sorted by include path."""
    out = {}
    for path in (CPP_INCLUDE / "hovering").rglob("*.hpp"):
        rel = path.relative_to(CPP_INCLUDE).as_posix()
        if rel.split("/")[1] not in CPP_EXCLUDED:
            out[rel] = path
    out.update(CPP_GENERATED)
    return dict(sorted(out.items()))


def _strip_template(head: str) -> str:
    """``head`` without a leading ``template <...>`` (balanced angle brackets)."""
    if not head.startswith("template"):
        return head
    depth = 0
    for i in range(head.index("<"), len(head)):
        depth += {"<": 1, ">": -1}.get(head[i], 0)
        if depth == 0:
            return head[i + 1 :].strip()
    return head


def _kind(head: str) -> str:
    """What a declaration (its text up to the body, initializer or ";") declares."""
    bare = _strip_template(head)
    if re.match(r"enum\b", bare):
        return "enum"
    if re.match(r"(class|struct|union)\b", bare) and "(" not in bare:
        return "class"
    # "(" before any "=" is a parameter list (a default argument may hold "="; operator= holds one).
    return "function" if "operator" in bare or "(" in bare.split("=")[0] else "variable"


def _closing(text: str, i: int) -> int:
    """Index just after the brace that closes the one at ``text[i]`` (literals and comments skipped)."""
    depth = 0
    while i < len(text):
        if text.startswith("//", i):
            i = text.find("\n", i)
            if i < 0:
                return len(text)
            continue
        c = text[i]
        if c in "\"'":
            i = _literal_end(text, i)
            continue
        depth += {"{": 1, "}": -1}.get(c, 0)
        i += 1
        if depth == 0:
            return i
    return len(text)


def _literal_end(text: str, i: int) -> int:
    """Index just after the string or character literal that starts at ``text[i]``."""
    j = i + 1
    while j < len(text) and text[j] != text[i]:
        j += 2 if text[j] == "\\" else 1
    return j + 1


def cpp_declarations(text: str, header: str = "") -> list[CppDeclaration]:
    """The public declarations of a header and their ``///`` comments.

    A small reader of the subset of C++ the public headers use (not a compiler): namespaces,
    classes and structs (their public and protected members; a struct's are public until a label
    says otherwise), enums and their enumerators, functions (an inline body is skipped),
    variables, constants and aliases (a braced initializer is shown as ``{...}``). A declaration's
    comment is the ``///`` lines right before it and a ``///<`` on the line it ends on. Skipped:
    preprocessor lines, plain ``//`` and ``/* */`` comments, forward declarations, ``friend`` and
    ``using namespace`` lines, private members and the namespace ``detail``.

    Parameters
    ----------
    text : str
        The header's text.
    header : str, optional
        Its include path, stored in each declaration.

    Returns
    -------
    list of CppDeclaration
        In the order of the header.
    """
    out: list[CppDeclaration] = []
    scopes: list[list[str]] = []  # [kind ("namespace", "class", "enum"), name, access]
    stmt: list[str] = []  # the declaration being read
    start = line = 1
    before: list[str] = []  # the /// lines waiting for the next declaration
    after: list[str] = []  # a ///< read before its declaration ended (an enumerator's last)
    ended = 0  # the line the last declaration ended on (a ///< there belongs to it)

    def head() -> str:
        return " ".join("".join(stmt).split())

    def record(kind: str, txt: str) -> None:
        nonlocal ended
        doc = " ".join(" ".join(before + after).split())
        before.clear()
        after.clear()
        hidden = any(k == "class" and a == "private" or k == "namespace" and name == "detail" for k, name, a in scopes)
        ended = 0 if hidden else line  # a ///< after a private member is not the last public one's
        if not hidden:
            scope = "::".join(name for k, name, _ in scopes if k in ("class", "enum"))
            out.append(CppDeclaration(header, start, scope, kind, txt, doc))

    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            stmt.append(" ")
            i += 1
        elif c == "#" and not text[text.rfind("\n", 0, i) + 1 : i].strip():
            while i < n and not (text[i] == "\n" and text[i - 1] != "\\"):  # with its continuations
                line += text[i] == "\n"
                i += 1
        elif text.startswith("/*", i):
            end = text.index("*/", i) + 2
            line += text.count("\n", i, end)
            i = end
        elif text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
            comment, pending = text[i:end], bool(head())
            if comment.startswith("///<"):
                if pending:
                    after.append(comment[4:])
                elif out and ended == line:
                    out[-1] = dataclasses.replace(out[-1], doc=" ".join(f"{out[-1].doc} {comment[4:]}".split()))
            elif comment.startswith("///") and not pending:
                before.append(comment[3:])
            i = end
        elif c in "\"'":
            end = _literal_end(text, i)
            stmt.append(text[i:end])
            i = end
        else:
            if not head() and not c.isspace():
                start = line
            kind = scopes[-1][0] if scopes else "namespace"
            txt = head()
            i += 1
            if kind == "enum" and c in ",}":
                if txt:
                    record("enumerator", txt)
                stmt.clear()
                if c == "}":
                    scopes.pop()
            elif kind == "class" and c == ":" and txt in ("public", "protected", "private") and text[i] != ":":
                scopes[-1][2] = txt
                stmt.clear()
            elif c == ";":
                bare = _strip_template(txt)
                if re.fullmatch(r"(class|struct|union) \w+", bare) or bare.startswith(("friend ", "using namespace ")):
                    before.clear()  # a forward declaration: nothing to document
                elif txt:
                    record(_kind(txt), txt)
                stmt.clear()
            elif c == "{":
                what = _kind(txt)
                if re.match(r"(inline )?namespace\b", txt):
                    scopes.append(["namespace", txt.split()[-1], "public"])
                    before.clear()
                    stmt.clear()
                elif what in ("class", "enum"):
                    record(what, txt)
                    bare = _strip_template(txt)
                    name = re.match(r"(?:enum )?(?:class|struct|union)? ?(\w+)", bare.removeprefix("enum ")).group(1)
                    scopes.append([what, name, "private" if bare.startswith("class") else "public"])
                    stmt.clear()
                elif what == "function":  # with its body, which is skipped
                    record(what, txt)
                    end = _closing(text, i - 1)
                    line += text.count("\n", i, end)
                    i = end
                    stmt.clear()
                else:  # a braced initializer: the declaration ends at its ";"
                    end = _closing(text, i - 1)
                    line += text.count("\n", i, end)
                    i = end
                    stmt.append(" {...}" if "=" in txt else "{...}")
            elif c == "}":
                if scopes:
                    scopes.pop()
                stmt.clear()
            else:
                stmt.append(c)
    return out


def _md_text(text: str) -> str:
    """A comment as Markdown text: its `code` spans kept, every other markup character literal."""
    parts = text.split("`")
    if len(parts) % 2 == 0:  # an unpaired backtick: no code spans
        parts = [text]
    return "`".join(p if k % 2 else re.sub(r"([\\*_{}\[\]<>#+!|$~-])", r"\\\1", p) for k, p in enumerate(parts))


def _file_comment(text: str) -> str:
    """The first paragraph of a header's leading ``//`` comment."""
    lines = []
    for ln in text.splitlines():
        s = ln.strip()
        if s.startswith("#") and not lines:
            continue
        if not s.startswith("//") or s.startswith("///"):
            break
        body = s[2:].strip()
        if not body and lines:
            break
        if body:
            lines.append(body)
    return " ".join(lines)


def write_cpp_page(where: Path, headers: dict | None = None) -> None:
    """The C++ API page: per public header, its comment and every declaration with its ``///`` comment.

    Parameters
    ----------
    where : Path
        The page to write (Markdown).
    headers : dict, optional
        ``{include path: file}``; default :func:`public_headers`.
    """
    parts = [
        "# C++ API",
        "",
        "The C++ library's public headers, as `cmake --install` installs them (see {doc}`../install`):",
        "every declaration with its `///` comment, generated from the headers at each docs build.",
        "Everything is in `namespace hovering`; link `hovering::core` (CMake: `find_package(hovering CONFIG",
        "REQUIRED)`) and include `hovering/hovering.hpp` for both models, or a header of its own.",
        "",
    ]
    for rel, path in (public_headers() if headers is None else headers).items():
        text = path.read_text()
        parts += [f"## `{rel}`", ""]
        about = _file_comment(text)
        if about:
            parts += [_md_text(about), ""]
        decls = cpp_declarations(text, rel)
        if not decls:
            includes = re.findall(r'#include "(hovering/[^"]+)"', text)
            parts += ["Includes " + ", ".join(f"`{h}`" for h in includes) + ".", ""] if includes else []
            continue
        for d in decls:
            indent = "  " * d.scope.count("::") + ("  " if d.scope else "")
            doc = f" — {_md_text(d.doc)}" if d.doc else ""
            parts.append(f"{indent}- `{d.text}`{doc}")
        parts.append("")
    _write(where, "\n".join(parts))


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
