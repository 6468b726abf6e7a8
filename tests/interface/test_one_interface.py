"""One interface for both models: the analyses run on TruncatedMap, TruncatedFamily and FlowMap
alike, and the enums are the core's own."""

from __future__ import annotations

import enum

import numpy as np
import pytest

import hovering as hv
from hovering import Region, Status, paper


@pytest.fixture(scope="module")
def maps():
    m = paper.truncated_map(0.1)
    fam = hv.TruncatedFamily.from_map(
        m, np.concatenate([-(np.linspace(1.0, 0.0, 81) ** 2), np.linspace(0.02, 1.0, 30)])
    )
    return {"TruncatedMap": m, "TruncatedFamily": fam, "FlowMap": paper.flow_map(-0.05)}


@pytest.mark.parametrize("kind", ["TruncatedMap", "TruncatedFamily", "FlowMap"])
def test_every_analysis_runs_on_every_map(maps, kind):
    m = maps[kind]
    assert isinstance(m, hv.ReturnMap)
    th = m.theory()
    assert th.hovers  # all three hover (the flow at eps = -0.05: sin(Omega0/2) < 0)
    hov = hv.hovering_area(m, n_steps=400, n_samples=400)
    assert hov.area > 0 and abs(hov.area - th.area) < hov.error + 0.25 * th.area
    assert hov.area_both_sides == pytest.approx(hov.area)  # near the tangency all of HOV is hovering proper
    cc = hv.critical_curve(m, n_steps=600, n_grid=16, tol=1e-3)
    # eq:kcrit: within O(eps^2) (and the flow's forcing b_1 eps) of the prediction, rotation to O(eps^2)
    assert cc.hovers and abs(cc.K_min - th.K_crit) < 0.5 * abs(th.K_crit)
    assert abs(cc.rotation - th.rho_crit) < 0.05
    res = m.iterate(m.L1(np.array([0.02])), np.array([0.02]), 400, record=("orbit", "regions"))
    rho_b = hv.rotation_number(res, "birkhoff")[0]
    rho_m = hv.rotation_number(res, "mean")[0]
    assert abs(rho_b - rho_m) < 0.01 and hv.regularity(res)[0] > 5
    assert abs(rho_b - (th.Omega0 + th.tau0 * 0.02)) < 0.1  # rho1(K0) to O(eps)


def test_enums_are_the_cores():
    # Bound from C++ (py::native_enum), not mirrored by hand: the classes are the core's.
    for E in (Region, Status, hv.FlowStatus, hv.Geometry):
        assert issubclass(E, enum.IntEnum) and E is getattr(hv._core, E.__name__)
    assert [r.label for r in Region] == ["-", "0u", "0", "1", "R", "m"]
    assert Region.parse("0u") is Region.BESIDE and Region.parse(4) is Region.MULTI
    assert int(Status.OFF_SECTION) == 9 and Status(2) is Status.EXITED
    with pytest.raises(ValueError, match="unknown region"):
        Region.parse("above the step")


OLD_PATHS = [  # (old module, name, the object it must still give)
    ("maps", "TruncatedMap", lambda: hv.TruncatedMap),
    ("geometry", "K_crit", lambda: hv.K_crit),
    ("fullmap", "TangentialCurve", lambda: hv.TangentialCurve),
    ("system", "Section", lambda: hv.Section),
    ("system", "to_normal", lambda: hv.to_normal),
    ("potentials", "CustomPotential", lambda: hv.CustomPotential),
    ("accuracy", "work_precision", lambda: hv.work_precision),
    ("references", "scipy_return_map", lambda: hv.diagnostics.scipy_return_map),
    ("plotting", "phase_portrait", lambda: hv.pipeline.phase_portrait),
    ("figures", "render", lambda: hv.plot.figures.render),
    ("scenes", "run_scene", lambda: hv.pipeline.run_scene),
    ("scenes", "redraw", lambda: hv.pipeline.redraw),
]


@pytest.mark.parametrize("old,name,new", OLD_PATHS)
def test_old_module_paths_still_work_and_warn(old, name, new):
    # Every old path keeps working for one release and says what replaces it and when it goes.
    import importlib

    import hovering.pipeline  # noqa: F401  (the new homes the expected objects are read from)
    import hovering.plot.figures  # noqa: F401

    mod = importlib.import_module(f"hovering.{old}")
    with pytest.warns(
        DeprecationWarning,
        match=rf"hovering\.{old}\.{name} is deprecated and will be removed in "
        rf"hovering 0\.4\.0; use hovering\.[\w.]+\.{name} instead",
    ):
        value = getattr(mod, name)
    assert value is new()
    with pytest.raises(AttributeError):
        _ = mod.no_such_name


def test_stubs_name_what_the_compiled_module_has():
    # One stub per compiled submodule (boost-histogram's pattern): every class and function a stub
    # declares exists in the module, and every public name of the module has a stub.
    import ast
    import pathlib

    stubs = pathlib.Path(hv.__file__).parent / "_core"
    for name, mod in (
        ("__init__", hv._core),
        ("truncated", hv._core.truncated),
        ("flow", hv._core.flow),
        ("normal", hv._core.normal),
    ):
        tree = ast.parse((stubs / f"{name}.pyi").read_text())
        declared = {n.name for n in tree.body if isinstance(n, (ast.ClassDef, ast.FunctionDef))}
        declared.discard("_MapCore")  # the stubs' common base of the two map classes, not a runtime name
        assert declared <= set(dir(mod)), (name, declared - set(dir(mod)))
        public = {
            k
            for k, v in vars(mod).items()
            if not k.startswith("__") and (callable(v) or isinstance(v, type)) and not isinstance(v, type(hv._core))
        }
        assert public <= declared, (name, public - declared)
