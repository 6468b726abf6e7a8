"""The C++ reading of the sweep scenes (hovering._core.scene.parse_sweep_scene) against Python's schema.

Python's parse_scene(tomllib.loads(text), Path(name), check_output=False) is the specification:
for every example scene of the sweep kinds the C++ values must be the same doubles, and for every
broken scene of the corpus the same message, word for word. Expressions are compared through the
one field nothing else checks (a hovering_area eps value), colours with matplotlib's is_color_like.
"""

import copy
import re
import struct
import tomllib
from pathlib import Path

import pytest
from matplotlib.colors import is_color_like

from hovering._core import scene as cscene
from hovering.scenes.schema import parse_scene
from hovering.scenes.spec import FLOW_KINDS, KINDS

ROOT = Path(__file__).resolve().parents[1]
SCENE_FILES = sorted((ROOT / "examples" / "scenes").glob("*.toml")) + sorted(
    (ROOT / "python" / "hovering" / "scenes" / "data").glob("*.toml"))
SWEEP_KINDS = ("hovering_area", "flow_hovering_area")
HOV_TEXT = (ROOT / "examples" / "scenes" / "fig_hov_vs_eps.toml").read_text()
FLOW_TEXT = (ROOT / "examples" / "scenes" / "flow_hov_vs_eps.toml").read_text()
HOV = tomllib.loads(HOV_TEXT)
FLOW = tomllib.loads(FLOW_TEXT)


# ------------------------------------------------------------------------------------------------
# A small TOML writer for the mutated scenes (no TOML writer is a dependency)


class Raw(str):
    """TOML written as is (dates, times)."""


def toml_str(s: str) -> str:
    out = []
    for ch in s:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def toml_key(k: str) -> str:
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else toml_str(k)


def toml_value(v) -> str:
    if isinstance(v, Raw):
        return str(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)  # 'inf', '-inf' and 'nan' are TOML too
    if isinstance(v, str):
        return toml_str(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{toml_key(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def dump(d: dict) -> str:
    """Root values first, then [tables] and [[arrays of tables]] (nested tables inline)."""
    lines, later = [], []
    for k, v in d.items():
        if isinstance(v, dict):
            later += [f"[{toml_key(k)}]"] + [f"{toml_key(a)} = {toml_value(b)}" for a, b in v.items()]
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for x in v:
                later += [f"[[{toml_key(k)}]]"] + [f"{toml_key(a)} = {toml_value(b)}" for a, b in x.items()]
        else:
            lines.append(f"{toml_key(k)} = {toml_value(v)}")
    return "\n".join(lines + later) + "\n"


DELETE = object()


def mutate(base: dict, *changes) -> dict:
    """A deep copy with (path, value) changes; a path is a tuple of keys/indices, DELETE removes."""
    d = copy.deepcopy(base)
    for path, value in changes:
        node = d
        for p in path[:-1]:
            node = node[p]
        if value is DELETE:
            del node[path[-1]]
        else:
            node[path[-1]] = value
    return d


# ------------------------------------------------------------------------------------------------
# The two readings


def py_dict(spec) -> dict:
    """Python's spec as the binding's dict (the same names)."""
    d = dict(name=spec.name, kind=spec.kind, title=spec.title, output=str(spec.output), dpi=spec.dpi,
             n_steps=spec.n_steps, samples=spec.samples, seed=spec.seed, eps=tuple(spec.eps))
    if spec.kind == "hovering_area":
        d["series"] = [dict(Omega0=s.Omega0, theta_w=s.theta_w, tau0=s.tau0, tau1=s.tau1, lam=s.lam, label=s.label,
                            golden_c=s.golden_c, K_low=s.K_low, color=s.color) for s in spec.series]
    else:
        pot = lambda p: dict(kind=p.kind, omega=p.omega, alpha=p.alpha)  # noqa: E731
        sy = spec.system
        d["system"] = dict(V1=pot(sy.V1), V2=pot(sy.V2), coupling=tuple(sy.coupling), eps=sy.eps, qw1=sy.qw1,
                           qw2=sy.qw2, geometry=sy.geometry)
        d["h"] = spec.h
        it = spec.integrator
        d["integrator"] = dict(stepper=it.stepper, rtol=it.rtol, atol=it.atol, accuracy=it.accuracy)
        d["models"] = tuple(spec.models)
    return d


def same(a, b) -> bool:
    """Equal, with floats equal to the bit (and of the same Python types)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        return struct.pack("<d", a) == struct.pack("<d", b)
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b


def python_reading(text: str, name: str):
    """("ok", dict) or ("error", message) from Python's schema."""
    try:
        return "ok", py_dict(parse_scene(tomllib.loads(text), Path(name), check_output=False))
    except ValueError as e:
        return "error", str(e)


def cpp_reading(text: str, name: str):
    try:
        return "ok", cscene.parse_sweep_scene(text, name)
    except ValueError as e:
        return "error", str(e)


# ------------------------------------------------------------------------------------------------
# 1. Valid scenes: the same values


def _kind(path: Path) -> str:
    return tomllib.loads(path.read_text())["kind"]


def test_the_examples_hold_both_sweep_kinds():
    kinds = {p.name: _kind(p) for p in SCENE_FILES}
    assert kinds["fig_hov_vs_eps.toml"] == "hovering_area"
    assert kinds["flow_hov_vs_eps.toml"] == "flow_hovering_area"
    assert kinds["demo.toml"] not in SWEEP_KINDS  # the packaged demo is a portrait: no sweep to compare


@pytest.mark.parametrize("path", [p for p in SCENE_FILES if _kind(p) in SWEEP_KINDS], ids=lambda p: p.name)
def test_example_scene_same_values(path):
    text = path.read_text()
    py, cc = python_reading(text, path.name), cpp_reading(text, path.name)
    assert py[0] == cc[0] == "ok"
    assert same(py[1], cc[1]), (py[1], cc[1])


VALID_VARIANTS = {
    "hov_golden_map_klow_colours": mutate(
        HOV, (("map",), {"tau0": "1.5", "tau1": 0.25, "lam": "sqrt(2)/3"}), (("dpi",), 300), (("title",), DELETE),
        (("output",), "./out//a/./b.png/"), (("series", 1, "color"), "tab:blue"), (("series", 2, "color"), "#abc"),
        (("series", 0, "K_low"), "-2*pi/3"), (("series", 1, "K_low"), -0.5), (("samples",), 7), (("seed",), 2**63 - 1),
        (("figsize",), [6, "3.5"])),
    "hov_expressions": mutate(
        HOV, (("eps",), ["-OMEGA_G/100", "1e-3", 0, "2**-4", "cos(pi/3)/10", "(sqrt)(2)/10"]),
        (("series", 0, "Omega0"), "2*pi*(sqrt(5)-1)/2"), (("series", 0, "theta_w"), "acos(-0.5)"),
        (("series", 3, "theta_w"), 2), (("series", 3, "tau1"), "-0.3")),
    "flow_everything": mutate(
        FLOW, (("system", "V1"), {"kind": "tan", "omega": "1", "alpha": 0.3}),
        (("system", "coupling"), [[0.5, 1, 1], ["1/3", 2, 0], [0.25, 1, 1]]), (("system", "eps"), "-0.2"),
        (("system", "qw1"), -0.75), (("system", "qw2"), "-1/3"), (("section", "h"), "2.5"),
        (("integrator",), {"accuracy": "1e-9"}), (("models",), []), (("samples",), 16), (("seed",), 12),
        (("outputs",), {"record": ["regions", "regions"]}), (("dpi",), 30)),
    "flow_defaults": mutate(
        FLOW, (("system", "coupling"), "none"), (("section",), DELETE), (("integrator",), {"rtol": 1e-8}),
        (("models",), ["measured"]), (("samples",), DELETE), (("seed",), DELETE), (("title",), DELETE),
        (("system", "eps"), Raw("-1e-400"))),
    "flow_integrator": mutate(FLOW, (("integrator",), {"stepper": "exact", "atol": "1e-12"}), (("system", "eps"), 0.0)),
}


@pytest.mark.parametrize("name", sorted(VALID_VARIANTS))
def test_valid_variant_same_values(name):
    text = dump(VALID_VARIANTS[name])
    py, cc = python_reading(text, f"{name}.toml"), cpp_reading(text, f"{name}.toml")
    assert py[0] == "ok", py[1]
    assert cc[0] == "ok", cc[1]
    assert same(py[1], cc[1]), (py[1], cc[1])


# ------------------------------------------------------------------------------------------------
# 2. Broken scenes: the same message


def _broken() -> dict:
    s1 = ("series", 1)
    h = {
        "root_unknown_keys": mutate(HOV, (("zeta",), 1), (("alpha",), "x")),
        "root_missing_output": mutate(HOV, (("output",), DELETE)),
        "root_missing_n_steps": mutate(HOV, (("n_steps",), DELETE)),
        "root_missing_series": mutate(HOV, (("series",), DELETE)),
        "root_missing_kind": mutate(HOV, (("kind",), DELETE)),
        "kind_not_a_string": mutate(HOV, (("kind",), 5)),
        "kind_blank": mutate(HOV, (("kind",), " \t")),
        "kind_unknown": mutate(HOV, (("kind",), "hovering")),
        "title_not_a_string": mutate(HOV, (("title",), 3)),
        "output_blank": mutate(HOV, (("output",), "")),
        "dpi_low": mutate(HOV, (("dpi",), 10)),
        "dpi_float": mutate(HOV, (("dpi",), 150.0)),
        "dpi_bool": mutate(HOV, (("dpi",), True)),
        "figsize_short": mutate(HOV, (("figsize",), [1])),
        "figsize_small": mutate(HOV, (("figsize",), [0.1, 5])),
        "map_unknown_key": mutate(HOV, (("map", "Tau0"), 1.0)),
        "map_not_a_table": mutate(HOV, (("map",), 3)),
        "map_theta_w_range": mutate(HOV, (("map", "theta_w"), 4)),
        "map_lam_zero": mutate(HOV, (("map", "lam"), 0)),
        "n_steps_zero": mutate(HOV, (("n_steps",), 0)),
        "n_steps_string": mutate(HOV, (("n_steps",), "10")),
        "eps_empty": mutate(HOV, (("eps",), [])),
        "eps_scalar": mutate(HOV, (("eps",), 0.1)),
        "eps_twice": mutate(HOV, (("eps",), [0.1, 0.2, 0.1])),
        "eps_signed_zero_twice": mutate(HOV, (("eps",), [0.0, -0.0])),
        "eps_too_many": mutate(HOV, (("eps",), [i / 1000 for i in range(201)])),
        "eps_division_by_zero": mutate(HOV, (("eps",), [0.1, "1/0"])),
        "eps_bool": mutate(HOV, (("eps",), [True])),
        "series_empty": mutate(HOV, (("series",), [])),
        "series_not_tables": mutate(HOV, (("series",), [1, 2])),
        "series_too_many": mutate(HOV, (("series",), [HOV["series"][0]] * 37)),
        "series_unknown_keys": mutate(HOV, (s1 + ("colour",), "red"), (s1 + ("Golden_c",), 1)),
        "series_missing_label": mutate(HOV, (("series", 0, "label"), DELETE)),
        "series_golden_and_Omega0": mutate(HOV, (s1 + ("Omega0",), 1.0)),
        "series_golden_and_theta_w": mutate(HOV, (s1 + ("theta_w",), 1.0)),
        "golden_c_range": mutate(HOV, (s1 + ("golden_c",), 1.5)),
        "golden_c_domain_error": mutate(HOV, (s1 + ("golden_c",), "sqrt(-1)")),
        "golden_c_tau0_zero": mutate(HOV, (("map", "tau0"), 0)),
        "golden_omega0_too_large": mutate(HOV, (("eps",), [0.1, 1e7])),
        "series_missing_Omega0": mutate(HOV, (("series", 0, "Omega0"), DELETE)),
        "series_missing_theta_w": mutate(HOV, (("series", 3, "theta_w"), DELETE)),
        "label_empty": mutate(HOV, (("series", 0, "label"), "")),
        "label_unicode_space": mutate(HOV, (("series", 0, "label"), " \u3000\u2003")),
        "colour_unknown": mutate(HOV, (("series", 0, "color"), "notacolour")),
        "colour_hex_length": mutate(HOV, (("series", 0, "color"), "#12345")),
        "colour_number": mutate(HOV, (("series", 0, "color"), 7)),
        "colour_quote_repr": mutate(HOV, (("series", 0, "color"), "it's")),
        "K_low_positive": mutate(HOV, (("series", 0, "K_low"), 0.5)),
        "K_low_below_band": mutate(HOV, (("series", 0, "K_low"), -1e7)),
        "K_low_below_band_golden": mutate(HOV, (s1 + ("K_low",), "-2e6")),
        "theta_w_is_pi": mutate(HOV, (("series", 0, "theta_w"), "pi")),
        "Omega0_beyond_map_limit": mutate(HOV, (("series", 0, "Omega0"), 2e6)),
        "samples_zero": mutate(HOV, (("samples",), 0)),
        "seed_negative": mutate(HOV, (("seed",), -1)),
        "seed_float": mutate(HOV, (("seed",), 1.5)),
        "lam_infinite": mutate(HOV, (("series", 0, "lam"), "1e400")),
        "lam_toml_inf": mutate(HOV, (("series", 0, "lam"), float("inf"))),
        "lam_toml_nan": mutate(HOV, (("series", 0, "lam"), float("nan"))),
        "Omega0_syntax": mutate(HOV, (("series", 0, "Omega0"), "2**")),
        "Omega0_too_long": mutate(HOV, (("series", 0, "Omega0"), "1+" * 100 + "1")),
        "Omega0_unknown_name": mutate(HOV, (("series", 0, "Omega0"), "tau*2")),
        "Omega0_control_characters": mutate(HOV, (("series", 0, "Omega0"), "1\n2\t\x7f\u00a0\u2028é")),
        "tau1_list": mutate(HOV, (("series", 0, "tau1"), [1, 2.5, "x"])),
        "tau1_table": mutate(HOV, (("series", 0, "tau1"), {"b": 1, "a": [True, 0.1]})),
        "Omega0_date": mutate(HOV, (("series", 0, "Omega0"), Raw("1979-05-27"))),
        "Omega0_time": mutate(HOV, (("series", 0, "Omega0"), Raw("07:32:00.25"))),
        "Omega0_local_datetime": mutate(HOV, (("series", 0, "Omega0"), Raw("1979-05-27T07:32:05"))),
        "Omega0_offset_datetime": mutate(HOV, (("series", 0, "Omega0"), Raw("1979-05-27T07:32:00-05:30"))),
        "Omega0_utc_datetime": mutate(HOV, (("series", 0, "Omega0"), Raw("1979-05-27T00:00:00.5Z"))),
    }
    f = {
        "flow_root_unknown_key": mutate(FLOW, (("series",), [{"label": "a"}])),
        "flow_missing_system": mutate(FLOW, (("system",), DELETE)),
        "flow_missing_eps": mutate(FLOW, (("eps",), DELETE)),
        "flow_system_not_a_table": mutate(FLOW, (("system",), "harmonic")),
        "flow_system_unknown_key": mutate(FLOW, (("system", "omega"), 1)),
        "flow_system_missing_V1": mutate(FLOW, (("system", "V1"), DELETE)),
        "flow_potential_kind": mutate(FLOW, (("system", "V2", "kind"), "cubic")),
        "flow_potential_unknown_key": mutate(FLOW, (("system", "V2", "beta"), 1)),
        "flow_tan_missing_alpha": mutate(FLOW, (("system", "V2", "alpha"), DELETE)),
        "flow_harmonic_alpha": mutate(FLOW, (("system", "V1", "alpha"), 1.0)),
        "flow_omega_zero": mutate(FLOW, (("system", "V2", "omega"), 0)),
        "flow_alpha_huge": mutate(FLOW, (("system", "V2", "alpha"), 1e101)),
        "flow_coupling_name": mutate(FLOW, (("system", "coupling"), "cubic")),
        "flow_coupling_empty": mutate(FLOW, (("system", "coupling"), [])),
        "flow_coupling_short_term": mutate(FLOW, (("system", "coupling"), [[1, 1, 1], [1, 1]])),
        "flow_coupling_exponent": mutate(FLOW, (("system", "coupling"), [[1, 1, 21]])),
        "flow_coupling_float_exponent": mutate(FLOW, (("system", "coupling"), [[1, 1.5, 1]])),
        "flow_coupling_too_many": mutate(FLOW, (("system", "coupling"), [[1, 1, 1]] * 65)),
        "flow_eps_without_coupling": mutate(FLOW, (("system", "coupling"), "none"), (("system", "eps"), 0.5)),
        "flow_system_eps_range": mutate(FLOW, (("system", "eps"), 11)),
        "flow_qw1_zero": mutate(FLOW, (("system", "qw1"), 0)),
        "flow_qw2_outside_tan_well": mutate(FLOW, (("system", "qw2"), -3)),
        "flow_qw1_outside_tan_well": mutate(FLOW, (("system", "V1"), {"kind": "tan", "omega": 1.0, "alpha": 2.0}),
                                            (("system", "qw1"), "-pi/4")),
        "flow_geometry_none": mutate(FLOW, (("system", "geometry"), "none")),
        "flow_geometry_unknown": mutate(FLOW, (("system", "geometry"), "corner")),
        "flow_h_below_step": mutate(FLOW, (("section", "h"), 0.1)),
        "flow_default_h_below_step": mutate(FLOW, (("section",), DELETE), (("system", "qw1"), -1.5)),
        "flow_h_negative": mutate(FLOW, (("section", "h"), -1)),
        "flow_section_unknown_key": mutate(FLOW, (("section", "energy"), 1)),
        "flow_section_missing_h": mutate(FLOW, (("section",), {})),
        "flow_section_not_a_table": mutate(FLOW, (("section",), 1)),
        "flow_integrator_unknown_key": mutate(FLOW, (("integrator", "method"), "rk4")),
        "flow_rtol_range": mutate(FLOW, (("integrator", "rtol"), 1)),
        "flow_atol_range": mutate(FLOW, (("integrator", "atol"), "1e-16")),
        "flow_stepper_unknown": mutate(FLOW, (("integrator", "stepper"), "euler")),
        "flow_accuracy_with_rtol": mutate(FLOW, (("integrator", "accuracy"), 1e-9)),
        "flow_accuracy_with_stepper_atol": mutate(FLOW, (("integrator",), {"stepper": "rk4", "atol": 1e-9,
                                                                           "accuracy": 1e-9})),
        "flow_accuracy_range": mutate(FLOW, (("integrator",), {"accuracy": 1})),
        "flow_record_not_a_list": mutate(FLOW, (("outputs",), {"record": "regions"})),
        "flow_record_empty": mutate(FLOW, (("outputs",), {"record": []})),
        "flow_record_trajectory": mutate(FLOW, (("outputs",), {"record": ["regions", "trajectory"]})),
        "flow_trajectory_dt": mutate(FLOW, (("outputs",), {"trajectory_dt": 0.1})),
        "flow_outputs_unknown_key": mutate(FLOW, (("outputs",), {"states": True})),
        "flow_eps_range": mutate(FLOW, (("eps",), [0.1, 2])),
        "flow_eps_twice": mutate(FLOW, (("eps",), ["0.1", 0.1])),
        "flow_models_not_a_list": mutate(FLOW, (("models",), "onset")),
        "flow_models_unknown": mutate(FLOW, (("models",), ["onset", "flow"])),
        "flow_n_steps_range": mutate(FLOW, (("n_steps",), 2_000_000)),
        "flow_samples_range": mutate(FLOW, (("samples",), 10)),
        "flow_seed_negative": mutate(FLOW, (("seed",), -5)),
        "flow_h_expression": mutate(FLOW, (("section", "h"), "1/0")),
    }
    # Float literals beyond the double range: inf to tomllib (toml++ refuses them; the C++ reads them as inf).
    h["eps_literal_overflow"] = mutate(HOV, (("eps",), [0.1, Raw("1e400")]))
    f["flow_literal_overflow_negative"] = mutate(FLOW, (("system", "eps"), Raw("-1_8e3_08")))
    cases = {k: dump(v) for k, v in {**h, **f}.items()}
    cases["literal_overflow_after_unicode"] = HOV_TEXT.split("[[series]]")[0] + (
        'series = [{label = "αβγ δ", tau1 = 0.5, Omega0 = +1.8e308, theta_w = 1.0}]\n')
    # Key order in messages is the file's (toml++ keeps tables sorted by key).
    cases["unknown_keys_in_file_order"] = HOV_TEXT.replace("[map]", "zz = 1\naa = 2\nmm = 3\n[map]", 1)
    cases["unknown_table_keys_in_file_order"] = FLOW_TEXT.replace("[system]", "[system]\nzz = 1\nV0 = 2", 1)
    title = 'title = "Area of the hovering set against eps (eq:hovsetsize)"\n'
    cases["title_table_repr_in_file_order"] = HOV_TEXT.replace(title, "") + "[title.z]\nx = 1\n[title]\nb = 2\na = 1\n"
    cases["title_array_of_tables_repr"] = HOV_TEXT.replace(title, "") + "[[title]]\nb = 1\n[[title]]\na = 2\n[title.zz]\n"
    cases["title_nested_values_repr"] = HOV_TEXT.replace(title, (
        'title = [[1, 2], [], [{}], {a.b = 1, "q k" = "v"}, 1979-05-27T07:32:00.999999999+14:00, 07:32:00, '
        '1979-05-27 07:32:00Z, 0xff, -0.0, +inf, -nan, 1e16, 12345678901234567.0, 0.000123, 5e-324]\n'))
    cases["colour_escapes_repr"] = dump(mutate(HOV, (("series", 0, "color"), "é😀\t\b\f\x00\x7f\x85\xad\u200b\ue000\U000e0001 \" ' \\")))
    cases["dotted_keys_order"] = FLOW_TEXT.replace("[section]", "[system.V3]\nz = 1\n[system.V0]\nb = 2\n[section]", 1)
    return cases


BROKEN = _broken()


def test_corpus_size():
    assert len(BROKEN) >= 60


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_broken_scene_same_message(name):
    where = "fig.toml" if not name.startswith("flow") else "flow.toml"
    py, cc = python_reading(BROKEN[name], where), cpp_reading(BROKEN[name], where)
    assert py[0] == "error", f"not a broken scene for Python: {py[1]}"
    assert cc == py


@pytest.mark.parametrize("kind", [k for k in KINDS if k not in SWEEP_KINDS])
def test_non_sweep_kind(kind):
    base = FLOW if kind in FLOW_KINDS else HOV
    text = dump(mutate(base, (("kind",), kind)))
    with pytest.raises(ValueError) as e:
        cscene.parse_sweep_scene(text, "scenes/pic.toml")
    assert str(e.value) == (
        f"pic.toml.kind = '{kind}': hovering_sweep runs the sweep kinds 'hovering_area' and 'flow_hovering_area'; "
        f"draw this scene with: python -m hovering scene scenes/pic.toml")


def test_toml_errors():
    # A byte-order mark is text to tomllib (toml++ would skip it): the same message.
    text = "\ufeff" + HOV_TEXT
    with pytest.raises(tomllib.TOMLDecodeError) as py:
        tomllib.loads(text)
    with pytest.raises(ValueError) as cc:
        cscene.parse_sweep_scene(text, "fig.toml")
    assert str(cc.value) == f"fig.toml: not valid TOML: {py.value}"
    # Elsewhere only the prefix is Python's: the parser's own detail differs.
    with pytest.raises(ValueError, match=r"^fig\.toml: not valid TOML: .*line 2"):
        cscene.parse_sweep_scene('kind = "hovering_area"\nn_steps = = 3\n', "fig.toml")


# ------------------------------------------------------------------------------------------------
# 3. Expressions: the same doubles, or the same error


EXPRESSIONS = [
    # values
    "1", "1 ", "1\n", "\n1", "(1\n+2)", "1 + \\\n2", "1 # comment", "# c\n1", "\f1", "1\n#x\n", "  \n1", "1\r",
    "(1\r\n+2)", "sqrt(4,)", "(sqrt)(4)", "((sqrt))(4)", "sqrt (4)", "1_0", "0x10", "0o17", "0b101", "0X_f",
    "00", "0_0", "01.5", "09.5", "1.", ".5", "1e5", "1E+5", "1.e-5", "1_0.5_0e1_0", "0e0", "1e-400",
    "2**-1", "-2**2", "2**3**2", "2 ** 0.5 ** 2", "+-+1", "-(1)", "--2", "0.1+0.2", "3*pi/4", "OMEGA_G",
    "cos(OMEGA_G)**2", "2*pi*(sqrt(5)-1)/2", "sin(-0.0)", "-0.0", "0*-1", "1e-5", "1.5e+16", "1e16/3",
    "123456789012345678901234567890", "0xffffffffffffffffffffffffffff", "0b" + "1" * 60, "2**0.5", "(-2)**3",
    "(-2.5)**2", "(-1)**1e300", "2**1023.9999", "10**-330", "1e-320**2", "0.5**1074.5", "0.0**0", "acos(-1)",
    "cos(1e308)", "sin(1e22)", "1e-310/1e10", "ｐｉ", "ｓｑｒｔ(2)", "-" * 199 + "1", "(" * 99 + "1" + ")" * 99,
    # not finite
    "1e400", "1e400-1e400", "1e308*10", "1e308+1e308", "sqrt(1e400)", "10**308*10",
    # errors
    " 1", "\t1", "1\n ", "1\r+1", "\\\n 1", "1 \\\n", "1\\", "1__0", "01", "0_1", "09", "0o8", "0b2", "0x", "1_",
    "1e", "1e+", "1.5_", "5._", "1j", "1.0j", "2**1024", "1/0", "0/0", "0**-1", "(-0.0)**-1", "(-8)**(1/3)",
    "(-10)**309", "(0.5)**-1100", "sqrt(-1)", "acos(2)", "sin(1e400)", "cos(-1e400)", "inf", "nan", "True", "pi pi",
    "[1]", "(1,)", "1,", "2**", "sqrt()", "sqrt(1,2)", "sqrt(x=4)", "sqrt(4)(5)", "pi(2)", "sqrt", "", " ",
    "1;", "1\x0b+1", "1 // 2", "1 % 2", "2***3", "1.5.5", "abs(-1)", "π", "１", "1\u00a02", "1 +", "(1", "1)",
    "1\x00", "2" * 400,
]


def _eps_scene(expr) -> str:
    return dump(mutate(HOV, (("eps",), [expr]), (("series",), [HOV["series"][0]])))


def test_expressions_cover_all_outcomes():
    outcomes = {python_reading(_eps_scene(e), "e.toml")[1] if python_reading(_eps_scene(e), "e.toml")[0] == "error"
                else "value" for e in EXPRESSIONS}
    assert "value" in outcomes
    assert any("must be finite" in o for o in outcomes)
    assert any("cannot evaluate" in o for o in outcomes)
    assert any("characters; allowed" in o for o in outcomes)


@pytest.mark.parametrize("expr", EXPRESSIONS, ids=repr)
def test_expression(expr):
    text = _eps_scene(expr)
    py, cc = python_reading(text, "e.toml"), cpp_reading(text, "e.toml")
    if py[0] == "ok":
        assert cc[0] == "ok", cc[1]
        assert struct.pack("<d", cc[1]["eps"][0]) == struct.pack("<d", py[1]["eps"][0]), (py[1]["eps"], cc[1]["eps"])
    else:
        assert cc == py


# ------------------------------------------------------------------------------------------------
# 4. Colours: is_color_like


COLOURS = [
    "red", "Red", "RED", "tab:blue", "TAB:Orange", "tab:grey", "xkcd:sky blue", "XKCD:Sky Blue", "xkcd:robin's egg",
    "C0", "C10", "C", "c0", "b", "B", "k", "w", "none", "NoNe", "#abc", "#ABCD", "#a1b2c3", "#a1b2c3d4", "#12345",
    "#ggg", "#", "0.5", " 0.25 ", "1", "1.5", "-0", "1e-1", "1_0e-1", ".5_0", "nan", "inf", "0x1", "grey", "gray",
    "lightgoldenrodyellow", "rebeccapurple", "darkgrey", "blanchedalmond", "notacolour", "re d", "0.\u0665",
    "\u3000 0.5", "blac\u212a", "\u212a", "C1\n",
]


def test_colours_cover_both_answers():
    answers = {is_color_like(c) for c in COLOURS}
    assert answers == {True, False}


@pytest.mark.parametrize("colour", COLOURS, ids=repr)
def test_colour(colour):
    text = dump(mutate(HOV, (("series", 0, "color"), colour)))
    py, cc = python_reading(text, "c.toml"), cpp_reading(text, "c.toml")
    assert (cc[0] == "ok") == is_color_like(colour)
    assert cc[0] == py[0]
    if py[0] == "ok":
        assert cc[1]["series"][0]["color"] == colour
    else:
        assert cc == py
