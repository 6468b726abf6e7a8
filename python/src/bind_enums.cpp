// The core's enums as Python enum.IntEnum classes (py::native_enum): one definition, in C++, of
// every region code and outcome that both models and the Python layer use.
#include <pybind11/native_enum.h>

#include "hovering/flow/return_map.hpp"
#include "hovering/truncated/map.hpp"
#include "hovering/types.hpp"
#include "pybind.hpp"

using namespace hovering;

void register_enums(py::module_& m) {
    py::native_enum<Region>(m, "Region", "enum.IntEnum",
                            "Region of Sigma_h a point lies in: how its segment passes the step before it returns.")
        .value("NONE", Region::None, "no return was taken from this point (the orbit had stopped)")
        .value("BESIDE", Region::Beside, "J_0u: passes beside the step without crossing q1 = qw1")
        .value("ABOVE", Region::Above, "J_0: crosses q1 = qw1 above the step, no impact (hovers)")
        .value("UPPER", Region::Upper, "J_1: one impact on the upper wall of the step")
        .value("RIGHT", Region::Right, "J_R: one impact on the right wall of the step")
        .value("MULTI", Region::Multi, "more than one impact (the flow only: outside the tangential band)")
        .finalize();
    py::native_enum<Status>(m, "Status", "enum.IntEnum", "Per-orbit outcome of an iteration (either model).")
        .value("OK", Status::Ok, "all requested steps were taken")
        .value("ESCAPED", Status::Escaped, "the orbit left the band where the map is defined")
        .value("EXITED", Status::Exited, "the orbit left the requested regions and stop_on_exit was set")
        .value("INTERRUPTED", Status::Interrupted, "the run was interrupted (Ctrl-C); the state reached is kept")
        .value("CORNER", Status::Corner, "flow: the orbit hit the corner of the step")
        .value("GRAZING", Status::Grazing, "flow: the orbit touched a wall tangentially")
        .value("STEP_LIMIT", Status::StepLimit, "flow: a return needed more integrator steps than max_steps")
        .value("NON_FINITE", Status::NonFinite, "flow: the state became non-finite (a runaway orbit)")
        .value("IMPACT_LIMIT", Status::ImpactLimit, "flow: more impacts in one return than max_impacts")
        .value("OFF_SECTION", Status::OffSection, "flow: the point is not on Sigma_h at this energy")
        .value("OUTSIDE_WELL", Status::OutsideWell, "flow: no accepted step keeps the state inside a bounded well")
        .value("STOPPED", Status::Stopped, "the orbit reached the set of its stop condition (hovering.Above / Below)")
        .value("IMPRECISE", Status::Imprecise, "flow: a return's verified error stayed above its band (FlowOptions.verify_steps)")
        .finalize();
    {
        py::native_enum<FlowStatus> e(m, "FlowStatus", "enum.IntEnum", "Outcome of one return of the flow.");
        for (const FlowStatusInfo& f : kFlowStatuses) e.value(f.name, f.status, f.doc);  // the core's one list
        e.finalize();
    }
    py::native_enum<TrajectoryPoint>(m, "TrajectoryPoint", "enum.IntEnum", "What a recorded trajectory point is.")
        .value("SAMPLE", TrajectoryPoint::Sample, "uniform sample at t = k dt of the orbit's clock")
        .value("IMPACT_IN", TrajectoryPoint::ImpactIn, "state at an impact before the reflection (on the wall)")
        .value("IMPACT_OUT", TrajectoryPoint::ImpactOut, "state at an impact after the reflection")
        .value("RETURN", TrajectoryPoint::Return, "the return to Sigma_h that ends a return")
        .value("END", TrajectoryPoint::End, "where a return stopped otherwise (corner, grazing, limits, interrupt)")
        .finalize();
    py::native_enum<Geometry>(m, "Geometry", "enum.IntEnum", "Which walls the flow sees.")
        .value("NONE", Geometry::None, "the smooth flow, no impact events")
        .value("WALL", Geometry::Wall, "the infinite wall q1 = qw1")
        .value("STEP", Geometry::Step, "the step {q1 < qw1, q2 < qw2}: right wall, upper wall, corner")
        .finalize();
    py::native_enum<Kernel>(m, "Kernel", "enum.IntEnum", "Implementation of the truncated map's batch step.")
        .value("SIMD", Kernel::Simd, "Eigen packets + SLEEF vector sin over chunks of orbits")
        .value("SCALAR", Kernel::Scalar, "one orbit at a time with libm sin (the reference)")
        .finalize();
    // The core's one wrap, for Python too (hovering._enums.wrap checks the range first).
    m.def("wrap", py::vectorize(&hovering::wrap_angle), py::arg("x"),
          "Angles wrapped to [-pi, pi) by the core's one definition (NaN stays NaN).");
}
