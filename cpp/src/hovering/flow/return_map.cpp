// The return map to Sigma_h: one return, and batches of returns on the core's thread pool.

#include "hovering/flow/return_map.hpp"

#include <cmath>
#include <mutex>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/detail/parallel.hpp"
#include "hovering/flow/tracer.hpp"

namespace hovering {

using detail::bad;
using detail::kNaN;

const std::array<FlowStatusInfo, 10> kFlowStatuses = {{
    {FlowStatus::Ok, "OK", "returned to Sigma_h"},
    {FlowStatus::Corner, "CORNER", "hit the corner of the step (the orbit stops)"},
    {FlowStatus::Grazing, "GRAZING", "touched a wall tangentially"},
    {FlowStatus::StepLimit, "STEP_LIMIT", "max_steps reached before returning"},
    {FlowStatus::NonFinite, "NON_FINITE", "the state became non-finite"},
    {FlowStatus::ImpactLimit, "IMPACT_LIMIT", "more impacts than max_impacts in one return (chattering)"},
    {FlowStatus::OffSection, "OFF_SECTION", "the starting point is not on Sigma_h at this energy"},
    {FlowStatus::Interrupted, "INTERRUPTED", "the batch was interrupted before this return ended"},
    {FlowStatus::OutsideWell, "OUTSIDE_WELL", "no accepted step keeps the state inside a bounded well"},
    {FlowStatus::Imprecise, "IMPRECISE", "a verified return's error stayed above its band at rtol / 10^4"},
}};

std::string describe(FlowStatus s) {
    const auto i = std::size_t(s);
    if (i >= kFlowStatuses.size()) return "status " + std::to_string(int(s));
    return std::string(kFlowStatuses[i].name) + " (" + kFlowStatuses[i].doc + ")";
}

Status orbit_status(FlowStatus s) {
    switch (s) {
        case FlowStatus::Ok:
            return Status::Ok;
        case FlowStatus::Corner:
            return Status::Corner;
        case FlowStatus::Grazing:
            return Status::Grazing;
        case FlowStatus::StepLimit:
            return Status::StepLimit;
        case FlowStatus::NonFinite:
            return Status::NonFinite;
        case FlowStatus::ImpactLimit:
            return Status::ImpactLimit;
        case FlowStatus::OffSection:
            return Status::OffSection;
        case FlowStatus::Interrupted:
            return Status::Interrupted;
        case FlowStatus::OutsideWell:
            return Status::OutsideWell;
        case FlowStatus::Imprecise:
            return Status::Imprecise;
    }
    return Status::NonFinite;
}

FlowWork& FlowWork::operator+=(const FlowWork& o) {
    field_evaluations += o.field_evaluations;
    coupling_evaluations += o.coupling_evaluations;
    wall_searches += o.wall_searches;
    section_searches += o.section_searches;
    label_operations += o.label_operations;
    dense_samples += o.dense_samples;
    steps += o.steps;
    return *this;
}

FlowWork& FlowWork::operator-=(const FlowWork& o) {
    field_evaluations -= o.field_evaluations;
    coupling_evaluations -= o.coupling_evaluations;
    wall_searches -= o.wall_searches;
    section_searches -= o.section_searches;
    label_operations -= o.label_operations;
    dense_samples -= o.dense_samples;
    steps -= o.steps;
    return *this;
}

void TrajectoryOutput::validate() const {
    if (!active()) return;
    if (!(dt > 0 && std::isfinite(dt))) bad("trajectory dt must be finite and > 0, got " + detail::fmt(dt));
    if (max_points_per_orbit < 1)
        bad("trajectory max_points_per_orbit must be >= 1, got " + std::to_string(max_points_per_orbit));
    if (!kinds) bad("trajectory kinds must be given with trajectory points");
}

Region region_of(const std::string& itinerary) {
    if (itinerary.size() > 1) return Region::Multi;
    if (itinerary == "u") return Region::Beside;
    if (itinerary == "0") return Region::Above;
    if (itinerary == "1") return Region::Upper;
    if (itinerary == "R") return Region::Right;
    return Region::None;
}

ReturnResult return_map(const FlowSystem& s, const std::array<double, 4>& z0, const FlowOptions& opt) {
    detail::gsl_quiet();
    opt.validate(s);
    s.validate();
    detail::Tracer tracer(s, opt);
    return tracer.trace(z0);
}

namespace {

// return_maps on validated s and opt, its tracers from pool (null: new ones).
void run_returns(detail::TracerPool* pool, const FlowSystem& s, const double* z0, std::int64_t n,
                 const FlowOptions& opt, int n_threads, const std::atomic<bool>* cancel, const ReturnMapsOutput& out,
                 std::atomic<std::int64_t>* progress) {
    if (n < 0) bad("number of orbits must be >= 0, got " + std::to_string(n));
    if (n_threads < 0 || n_threads > detail::kMaxThreads)
        bad("n_threads must be in [0, " + std::to_string(detail::kMaxThreads) + "] (0 = all cores), got " +
            std::to_string(n_threads));
    out.trajectory.validate();
    if (n == 0) return;
    auto write = [&](std::int64_t i, const ReturnResult& r) {
        for (int k = 0; k < 4; ++k)
            if (out.z) out.z[4 * i + k] = r.z[std::size_t(k)];  // a start off Sigma_h is NaN already
        if (out.time) out.time[i] = r.time;
        if (out.status) out.status[i] = static_cast<std::int8_t>(r.status);
        if (out.region)
            out.region[i] =
                static_cast<std::int8_t>(r.status == FlowStatus::Ok ? region_of(r.itinerary) : Region::None);
        if (out.energy_error) out.energy_error[i] = r.energy_error;
        if (out.steps) out.steps[i] = r.steps;
        if (out.itinerary) out.itinerary[i] = r.itinerary;
        if (out.chart) {
            out.chart[2 * i] = r.chart[0];
            out.chart[2 * i + 1] = r.chart[1];
        }
    };
    const int threads = detail::worker_count(n_threads, n);
    detail::WorkQueue queue(n, detail::balanced_block(n, threads, 16));
    const TrajectoryOutput& traj = out.trajectory;
    std::mutex mu;
    detail::run_workers(threads, queue, [&](detail::WorkCursor& cur) {
        // Returns side by side (8 lanes for stepper "taylor"): each lane takes the next orbit as
        // soon as its return is over; an orbit's result does not depend on its lane or partners.
        detail::PooledGroup pooled(pool, s, opt);
        detail::TracerGroup& group = *pooled;
        const int L = group.lanes();
        std::vector<detail::DenseRecorder> rec(static_cast<std::size_t>(L));
        std::vector<std::int64_t> idx(static_cast<std::size_t>(L), -1);
        auto done = [&](std::int64_t i, const ReturnResult& r) {
            write(i, r);
            if (progress) progress->fetch_add(1, std::memory_order_relaxed);
        };
        // Lane l takes orbits until one needs tracing (those that do not are written at once).
        auto fill = [&](int l) {
            for (std::int64_t i; cur.pop(i);) {
                const std::array<double, 4> a{z0[4 * i], z0[4 * i + 1], z0[4 * i + 2], z0[4 * i + 3]};
                if (traj.truncated) traj.truncated[i] = 0;
                ReturnResult r;
                r.z = a;
                if (cancel && cancel->load(std::memory_order_relaxed)) {
                    r.status = FlowStatus::Interrupted;
                } else if (!(std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]) &&
                             std::isfinite(a[3]))) {
                    r.status = FlowStatus::OffSection;
                } else {
                    if (traj.active()) {
                        rec[std::size_t(l)].start(&traj.points[i], &traj.kinds[i], traj.dt, traj.max_points_per_orbit);
                        group.lane(l).set_dense(&rec[std::size_t(l)]);
                    }
                    idx[std::size_t(l)] = i;
                    group.start(l, a, false, cancel);
                    return;
                }
                done(i, r);
            }
        };
        for (int l = 0; l < L; ++l) fill(l);
        while (group.any_busy()) {
            const unsigned over = group.step(cancel);
            for (int l = 0; l < L; ++l) {
                if (!((over >> l) & 1u)) continue;
                const std::int64_t i = idx[std::size_t(l)];
                const ReturnResult r = group.collect(l);
                if (traj.truncated) traj.truncated[i] = rec[std::size_t(l)].truncated ? 1 : 0;
                done(i, r);
                fill(l);
            }
        }
        if (out.work) {
            const FlowWork w = pooled.work();
            std::lock_guard<std::mutex> lock(mu);
            *out.work += w;
        }
    });
}

}  // namespace

void return_maps(const FlowSystem& s, const double* z0, std::int64_t n, const FlowOptions& opt, int n_threads,
                 const std::atomic<bool>* cancel, const ReturnMapsOutput& out, std::atomic<std::int64_t>* progress) {
    detail::gsl_quiet();
    opt.validate(s);
    s.validate();
    run_returns(nullptr, s, z0, n, opt, n_threads, cancel, out, progress);
}

ReturnMapper::ReturnMapper(const FlowSystem& s, const FlowOptions& opt) {
    detail::gsl_quiet();
    opt.validate(s);
    s.validate();
    pool_ = std::make_shared<detail::TracerPool>(s, opt);
}

void ReturnMapper::run(const double* z0, std::int64_t n, int n_threads, const std::atomic<bool>* cancel,
                       const ReturnMapsOutput& out, std::atomic<std::int64_t>* progress) const {
    run_returns(pool_.get(), pool_->system(), z0, n, pool_->options(), n_threads, cancel, out, progress);
}

ReturnResult ReturnMapper::one(const std::array<double, 4>& z0, FlowWork* work) const {
    ReturnResult r;
    r.z = z0;
    if (!(std::isfinite(z0[0]) && std::isfinite(z0[1]) && std::isfinite(z0[2]) && std::isfinite(z0[3]))) {
        r.status = FlowStatus::OffSection;
        return r;
    }
    // Lane 0 of a kept group, traced alone: an orbit's bits are the same alone or in a group
    // (taylor_kernel.hpp), and the group's step loop cost ~1.2 us of a one-point return.
    detail::PooledGroup pooled(pool_.get(), pool_->system(), pool_->options());
    r = pooled->lane(0).trace(z0, false, nullptr);
    if (work) *work = pooled.work();
    return r;
}

const FlowSystem& ReturnMapper::system() const {
    return pool_->system();
}

const FlowOptions& ReturnMapper::options() const {
    return pool_->options();
}

}  // namespace hovering
