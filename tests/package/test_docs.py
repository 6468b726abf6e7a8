"""The documentation site's generated pages (docs/_generate.py): every public name has an API
entry, in exactly one topic of the index; every example scene a gallery page; every declaration of
the public C++ headers a `///` comment on the C++ API page. The build itself (Sphinx, warnings as
errors) runs in `bash scripts/docs.sh`, which CI calls."""

from __future__ import annotations

import importlib
import re
import sys
import types
from pathlib import Path

import pytest

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


def _top_names() -> list[str]:
    return _generate.public_names(hovering)


def test_every_public_name_is_in_exactly_one_api_group():
    placed = [n for _, _, names in _generate.API_GROUPS for n in names]
    top = _top_names()
    for n in top:
        assert placed.count(n) == 1, f"hovering.{n} is in {placed.count(n)} groups of docs/_generate.py API_GROUPS"
    for n in placed:  # and nothing else: a subpackage's own name as "sub.Name"
        sub, _, name = n.rpartition(".")
        if sub:
            assert name in _generate.public_names(importlib.import_module(f"hovering.{sub}")), n
            assert name not in top, f"{n}: exported at the top level, list it as {name!r}"
        else:
            assert n in top, f"API_GROUPS lists {n!r}, which is not in hovering.__all__"
    # The modules of hovering.__all__ have sections of their own (or are old paths that only warn).
    modules = [n for n in hovering.__all__ if isinstance(getattr(hovering, n, None), types.ModuleType)]
    old = set(getattr(hovering, "_OLD_MODULES", ("geometry",)))
    assert {f"hovering.{m}" for m in modules if m not in old} <= set(_generate.SUBPACKAGES)


def test_the_api_index_is_grouped(tmp_path):
    _generate.write_api_pages(tmp_path)
    index = (tmp_path / "index.rst").read_text()
    for title, _, _ in _generate.API_GROUPS:
        assert f"\n{title}\n{'-' * len(title)}\n" in index, title
    # A name in a group is listed once: TransitResult in Results, not again under hovering.analysis.
    assert index.count("   TransitResult\n") == 1


def test_an_unplaced_public_name_stops_the_build(monkeypatch):
    groups = tuple((t, s, tuple(n for n in names if n != "transit")) for t, s, names in _generate.API_GROUPS)
    monkeypatch.setattr(_generate, "API_GROUPS", groups)
    with pytest.raises(ValueError, match=r"in no group \['transit'\]"):
        _generate.group_entries()


# ------------------------------------------------------------------------------- the C++ API page


def test_the_public_headers_are_those_cmake_installs():
    cmake = (DOCS.parent / "CMakeLists.txt").read_text()
    assert "install(DIRECTORY cpp/include/hovering ${_gen}/include/hovering" in cmake
    for d in _generate.CPP_EXCLUDED:
        assert f"PATTERN {d} EXCLUDE" in cmake
    headers = _generate.public_headers()
    assert "hovering/hovering.hpp" in headers and "hovering/version.hpp" in headers
    assert not any(h.startswith("hovering/sweep/") for h in headers)
    assert set(headers) - {"hovering/version.hpp"} == {
        p.relative_to(_generate.CPP_INCLUDE).as_posix()
        for p in (_generate.CPP_INCLUDE / "hovering").rglob("*.hpp")
        if "/sweep/" not in p.as_posix()
    }


def test_every_public_cpp_declaration_has_a_doc_comment():
    missing = [
        f"cpp/include/{d.header}:{d.line}: {d.text}"
        for rel, path in _generate.public_headers().items()
        for d in _generate.cpp_declarations(path.read_text(), rel)
        if not d.doc
    ]
    assert not missing, "public declarations without a /// comment:\n" + "\n".join(missing)


def test_the_header_reader():
    text = """#pragma once
// file comment
#include <vector>
namespace hovering {
namespace detail { class Hidden; struct Inner { int x; }; }
/// A thing.
template <class T>
class Thing {
public:
    /// Build it.
    explicit Thing(std::vector<double> v);
    /// Inline.
    double f(double x) const { if (x) { return 1; } return {}; }
    int n = 3;  ///< a member
    static constexpr const char* kName = "a;{b}";  ///< a constant with ; and { in it
protected:
    /// For subclasses.
    void g();
private:
    /// Private, left out.
    void h();
    double y_;  ///< private too
};
/// Which.
enum class Side : std::int8_t {
    A = 0,  ///< first
    B = 1   ///< last, no comma
};
std::array<double, 4> z{};  ///< braced
void undocumented(int a = (1 + 2));
}  // namespace hovering
"""
    decls = {d.text: d for d in _generate.cpp_declarations(text, "x.hpp")}
    assert list(decls) == [
        "template <class T> class Thing",
        "explicit Thing(std::vector<double> v)",
        "double f(double x) const",
        "int n = 3",
        'static constexpr const char* kName = "a;{b}"',
        "void g()",
        "enum class Side : std::int8_t",
        "A = 0",
        "B = 1",
        "std::array<double, 4> z{...}",
        "void undocumented(int a = (1 + 2))",
    ]
    assert decls["double f(double x) const"].doc == "Inline." and decls["double f(double x) const"].scope == "Thing"
    assert decls["int n = 3"].doc == "a member" and decls["B = 1"].doc == "last, no comma"
    assert decls["A = 0"].scope == "Side" and decls["std::array<double, 4> z{...}"].doc == "braced"
    assert decls["void undocumented(int a = (1 + 2))"].doc == "" and decls["void g()"].line == 18
    assert decls["void g()"].doc == "For subclasses." and decls["template <class T> class Thing"].doc == "A thing."


def test_the_cpp_page_lists_every_header_and_declaration(tmp_path):
    page = tmp_path / "cpp.md"
    _generate.write_cpp_page(page)
    text = page.read_text()
    for rel in _generate.public_headers():
        assert f"## `{rel}`" in text
    assert "`TruncatedMap make_truncated_map(" in text and "`class FlowMap`" in text
    assert "preimage_height" not in text  # private
