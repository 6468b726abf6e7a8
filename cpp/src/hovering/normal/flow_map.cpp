// The flow's return map as an iterable map: see flow_map.hpp.

#include "hovering/normal/flow_map.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/detail/parallel.hpp"
#include "hovering/flow/tracer.hpp"

namespace hovering {

using detail::bad;
using detail::fmt;
using detail::kNaN;
using detail::kPi;
using detail::kTwoPi;
using detail::wrap;

FlowMap::FlowMap(FlowSystem s, double h, FlowOptions opt, std::shared_ptr<const TangentialCurve> curve,
                 std::shared_ptr<const AnalyticArcs> lift)
    : s_(std::move(s)), h_(h), opt_(std::move(opt)), curve_(std::move(curve)), lift_(std::move(lift)) {
    detail::gsl_quiet();
    opt_.validate(s_);
    opt_ = opt_.resolved(s_);  // options() reports the stepper that runs, never "auto"
    s_.validate();
    if (!std::isfinite(h_)) bad("h must be finite, got " + fmt(h_));
    if (curve_) {
        if (!curve_->is_graph()) bad(curve_->not_graph_reason());
        if (curve_->h() != h_)
            bad("the tangential curve was measured at h = " + fmt(curve_->h()) + ", not at h = " + fmt(h_));
    }
    if (lift_) lift_->validate();
    const double E1 = h_ - s_.V1->V(s_.qw1);
    lift_I0_ = E1 > 0 ? s_.V2->action(E1) : 0.0;
    pool_ = std::make_shared<detail::TracerPool>(s_, opt_);
}

std::pair<double, double> FlowMap::to_section(double x, double y) const {
    const double th = wrap(x);
    return {th, curve_ ? y + curve_->I_tan(th) : y};
}

std::pair<double, double> FlowMap::from_section(double theta, double I) const {
    const double th = wrap(theta);
    return {th, curve_ ? I - curve_->I_tan(th) : I};
}

bool FlowMap::state(double x, double y, std::array<double, 4>& z, std::string* why) const {
    const auto [th, I] = to_section(x, y);
    return try_section_point(s_, h_, th, I, z, why);
}

double FlowMap::rotation_of(double x, double y, Region r, double x1) const {
    const double adv = wrap(x1 - x);
    if (!lift_) return adv < 0 ? adv + kTwoPi : adv;
    const double K = curve_ ? y : y - lift_I0_;
    const ArcLengths a = lift_->at(K);
    double ref = a.Omega;
    if (r == Region::Upper) ref += a.JR;
    if (r == Region::Right) ref -= a.J1;
    return ref + wrap(adv - ref);
}

bool FlowMap::advance_start(double x, double y, bool inverse, std::array<double, 4>& z, FlowStep& st,
                            const std::array<double, 2>* chart, const std::array<double, 4>* chart_point) const {
    auto [th, I] = to_section(x, y);
    if (inverse) th = -th;  // R2: theta -> -theta (section_point accepts [-pi, pi])
    if (chart && th == (*chart)[0] && I == (*chart)[1]) {
        // The last image's chart check solved this very point (same coordinates, same h_): in
        // section coordinates every start of an orbit but the first.
        z = *chart_point;
        return true;
    }
    if (try_section_point(s_, h_, th, I, z)) return true;
    st = FlowStep{};
    st.x = st.y = kNaN;
    st.ret.status = FlowStatus::OffSection;
    st.ret.z = {kNaN, kNaN, kNaN, kNaN};
    return false;
}

FlowStep FlowMap::advance_end(ReturnResult ret, bool inverse) const {
    FlowStep st;
    st.x = st.y = kNaN;
    st.ret = std::move(ret);
    if (st.ret.status != FlowStatus::Ok) return st;
    // ret.energy_error is |H(image) - H(start)|; the start solves H = h to rounding (1e-16).
    std::array<double, 2> c = st.ret.chart;  // the tracer's section_coordinates of z
    if (inverse) {
        c[0] = wrap(-c[0]);
        std::reverse(st.ret.itinerary.begin(), st.ret.itinerary.end());
    }
    const auto [x1, y1] = from_section(c[0], c[1]);
    st.x = x1;
    st.y = y1;
    st.region = region_of(st.ret.itinerary);
    return st;
}

namespace {

// The chart of H2's action-angle variables at (q, p) = point_at(theta, e): d(q, p)/dtheta =
// (p, -V') / omega and d(q, p)/dI = omega d(q, p)/de (Potential::point_slope), omega = de/dI.
struct Chart {
    double dth[2], dI[2], omega;
};
Chart chart(const Potential& V, double theta, double e, double q, double p) {
    const double w = V.frequency(e);
    const std::array<double, 2> v = V.point_slope(theta, e);
    return {{p / w, -V.dV(q) / w}, {w * v[0], w * v[1]}, w};
}

}  // namespace

void FlowMap::start_tangents(double x, const std::array<double, 4>& z, double I0, double* t0) const {
    // Sigma_h's chart: (q2, p2) = S2^{-1}(theta, I), p1 = 0, q1 from V1(q1) + eps Vc(q1, q2) = h - H2(I):
    // (V1' + eps Vc_1) dq1 = -(eps Vc_2 dq2 + omega dI).
    const double th = wrap(x);
    const double e2 = s_.V2->energy(I0);
    const Chart c = chart(*s_.V2, th, e2, z[2], z[3]);
    std::array<double, 2> g{0.0, 0.0};
    if (s_.eps != 0) g = s_.coupling.gradient(z[0], z[2]);
    const double F1 = s_.V1->dV(z[0]) + s_.eps * g[0], F2 = s_.eps * g[1];
    const double col_th[4] = {-F2 * c.dth[0] / F1, 0.0, c.dth[0], c.dth[1]};
    const double col_I[4] = {-(F2 * c.dI[0] + c.omega) / F1, 0.0, c.dI[0], c.dI[1]};
    // Map coordinates: (theta, I) = (x, y + I_tan(x)), so d/dx = d/dtheta + I_tan' d/dI, d/dy = d/dI.
    const double slope = curve_ ? curve_->I_tan_slope(th) : 0.0;
    for (int r = 0; r < 4; ++r) {
        t0[2 * r] = col_th[r] + slope * col_I[r];
        t0[2 * r + 1] = col_I[r];
    }
}

void FlowMap::end_jacobian(const FlowStep& st, double* J) const {
    for (int k = 0; k < 4; ++k) J[k] = kNaN;
    if (st.ret.status != FlowStatus::Ok) return;
    const std::array<double, 4>& z = st.ret.z;
    const std::array<double, 8>& T = st.ret.tangents;
    // Projection onto Sigma_h along the flow: the return time moves by -dp1 / (dp1/dt).
    double f[4];
    s_.rhs(z.data(), f);
    double dz[4][2];
    for (int j = 0; j < 2; ++j) {
        const double dt = -T[2 + j] / f[1];
        for (int r = 0; r < 4; ++r) dz[r][j] = T[2 * r + j] + f[r] * dt;
    }
    // (theta, I) = S2(q2, p2): the inverse of the chart [d/dtheta, d/dI] (determinant 1).
    const double e2 = 0.5 * z[3] * z[3] + s_.V2->V(z[2]);
    if (!(e2 > 0)) return;
    double th = s_.V2->angle_on_level(z[2], z[3], e2);
    if (th >= kPi) th -= kTwoPi;
    const Chart c = chart(*s_.V2, th, e2, z[2], z[3]);
    const double det = c.dth[0] * c.dI[1] - c.dI[0] * c.dth[1];
    const double D[4] = {c.dI[1] / det, -c.dI[0] / det, -c.dth[1] / det, c.dth[0] / det};
    double A[4];
    for (int j = 0; j < 2; ++j) {
        A[j] = D[0] * dz[2][j] + D[1] * dz[3][j];
        A[2 + j] = D[2] * dz[2][j] + D[3] * dz[3][j];
    }
    // Map coordinates: y1 = I1 - I_tan(theta1).
    const double slope = curve_ ? curve_->I_tan_slope(wrap(th)) : 0.0;
    J[0] = A[0];
    J[1] = A[1];
    J[2] = A[2] - slope * A[0];
    J[3] = A[3] - slope * A[1];
}

FlowJacobian FlowMap::jacobian(double x, double y) const {
    FlowJacobian out;
    jacobians(&x, &y, 1, 1, nullptr, &out);
    return out;
}

void FlowMap::jacobians(const double* x, const double* y, std::int64_t n, int n_threads,
                        const std::atomic<bool>* cancel, FlowJacobian* out) const {
    if (n < 0) bad("number of points must be >= 0, got " + std::to_string(n));
    if (n_threads < 0 || n_threads > detail::kMaxThreads)
        bad("n_threads must be in [0, " + std::to_string(detail::kMaxThreads) + "] (0 = all cores), got " +
            std::to_string(n_threads));
    for (std::int64_t i = 0; i < n; ++i) {
        detail::require_angle(x[i], "x[" + std::to_string(i) + "]");
        detail::require_finite(y[i], "y[" + std::to_string(i) + "]");
    }
    if (n == 0) return;
    const int threads = detail::worker_count(n_threads, n);
    detail::WorkQueue queue(n, detail::balanced_block(n, threads, 16));
    detail::run_workers(threads, queue, [&](detail::WorkCursor& cur) {
        // As steps(): one return per point, side by side, each carrying the chart's two tangents.
        detail::PooledGroup pooled(pool_.get(), s_, opt_, 2);
        detail::TracerGroup& group = *pooled;
        const int L = group.lanes();
        std::vector<std::int64_t> idx(static_cast<std::size_t>(L), -1);
        auto fill = [&](int l) {
            for (std::int64_t i; cur.pop(i);) {
                std::array<double, 4> z{};
                out[i] = FlowJacobian{};
                if (cancel && cancel->load(std::memory_order_relaxed)) {
                    out[i].step.x = out[i].step.y = kNaN;
                    out[i].step.ret.status = FlowStatus::Interrupted;
                } else if (advance_start(x[i], y[i], false, z, out[i].step)) {
                    double t0[8];
                    start_tangents(x[i], z, to_section(x[i], y[i]).second, t0);
                    idx[std::size_t(l)] = i;
                    group.start(l, z, false, cancel, t0);
                    return;
                }
            }
        };
        for (int l = 0; l < L; ++l) fill(l);
        while (group.any_busy()) {
            const unsigned over = group.step(cancel);
            for (int l = 0; l < L; ++l) {
                if (!((over >> l) & 1u)) continue;
                FlowJacobian& o = out[idx[std::size_t(l)]];
                o.step = advance_end(group.collect(l), false);
                end_jacobian(o.step, o.J);
                fill(l);
            }
        }
    });
}

FlowStep FlowMap::advance(detail::Tracer& tr, double x, double y, bool inverse, const std::atomic<bool>* cancel) const {
    std::array<double, 4> z{};
    FlowStep st;
    if (!advance_start(x, y, inverse, z, st)) return st;
    return advance_end(tr.trace(z, false, cancel), inverse);
}

FlowStep FlowMap::step(double x, double y) const {
    detail::require_angle(x, "step: x");
    detail::require_finite(y, "step: y");
    detail::PooledGroup pooled(pool_.get(), s_, opt_);
    return advance(pooled->lane(0), x, y, false, nullptr);
}

FlowStep FlowMap::step_inverse(double x, double y) const {
    detail::require_angle(x, "step_inverse: x");
    detail::require_finite(y, "step_inverse: y");
    detail::PooledGroup pooled(pool_.get(), s_, opt_);
    return advance(pooled->lane(0), x, y, true, nullptr);
}

void FlowMap::steps(const double* x, const double* y, std::int64_t n, bool inverse, int n_threads,
                    const std::atomic<bool>* cancel, FlowStep* out) const {
    if (n < 0) bad("number of points must be >= 0, got " + std::to_string(n));
    if (n_threads < 0 || n_threads > detail::kMaxThreads)
        bad("n_threads must be in [0, " + std::to_string(detail::kMaxThreads) + "] (0 = all cores), got " +
            std::to_string(n_threads));
    for (std::int64_t i = 0; i < n; ++i) {
        detail::require_angle(x[i], "x[" + std::to_string(i) + "]");
        detail::require_finite(y[i], "y[" + std::to_string(i) + "]");
    }
    if (n == 0) return;
    const int threads = detail::worker_count(n_threads, n);
    detail::WorkQueue queue(n, detail::balanced_block(n, threads, 16));
    detail::run_workers(threads, queue, [&](detail::WorkCursor& cur) {
        // One return per point, side by side in a TracerGroup (8 lanes for taylor).
        detail::PooledGroup pooled(pool_.get(), s_, opt_);
        detail::TracerGroup& group = *pooled;
        const int L = group.lanes();
        std::vector<std::int64_t> idx(static_cast<std::size_t>(L), -1);
        auto fill = [&](int l) {
            for (std::int64_t i; cur.pop(i);) {
                std::array<double, 4> z{};
                if (cancel && cancel->load(std::memory_order_relaxed)) {
                    out[i] = FlowStep{};
                    out[i].x = out[i].y = kNaN;
                    out[i].ret.status = FlowStatus::Interrupted;
                } else if (advance_start(x[i], y[i], inverse, z, out[i])) {
                    idx[std::size_t(l)] = i;
                    group.start(l, z, false, cancel);
                    return;
                }
            }
        };
        for (int l = 0; l < L; ++l) fill(l);
        while (group.any_busy()) {
            const unsigned over = group.step(cancel);
            for (int l = 0; l < L; ++l) {
                if (!((over >> l) & 1u)) continue;
                out[idx[std::size_t(l)]] = advance_end(group.collect(l), inverse);
                fill(l);
            }
        }
    });
}

void FlowMap::iterate(const double* x0, const double* y0, std::int64_t n, const FlowIterateOptions& opt,
                      const FlowIterateOutput& out) const {
    if (n < 0) bad("number of orbits must be >= 0, got " + std::to_string(n));
    opt.validate();
    if (opt.exit_mask && s_.geometry == Geometry::None)
        bad("regions need walls: the smooth flow (geometry none) labels no return, so exit regions cannot be watched");
    if (!opt.labels && (out.regions || out.visited || out.itinerary || out.rotation || out.residence || opt.exit_mask))
        bad("labels = false, but regions, visited, itinerary, rotation, residence or an exit_mask need the returns "
            "labelled");
    out.trajectory.validate();
    for (std::int64_t i = 0; i < n; ++i) {
        detail::require_angle(x0[i], "x0[" + std::to_string(i) + "]");
        detail::require_finite(y0[i], "y0[" + std::to_string(i) + "]");
    }
    if (n == 0) return;
    const std::int64_t ns = opt.n_steps, every = opt.every;
    const TrajectoryOutput& traj = out.trajectory;
    const std::int64_t np = recorded_states(ns, every), nr = recorded_returns(ns, every);  // per orbit
    const StopCondition& stop = opt.stop;

    // Point x_k of orbit i (k a multiple of every).
    auto record_point = [&](std::int64_t i, std::int64_t k, double x, double y, const std::array<double, 4>* z) {
        const std::int64_t at = i * np + k / every;
        if (out.orbit_x) out.orbit_x[at] = x;
        if (out.orbit_y) out.orbit_y[at] = y;
        if (out.orbit_theta || out.orbit_I) {
            const auto [th, I] = to_section(x, y);
            if (out.orbit_theta) out.orbit_theta[at] = th;
            if (out.orbit_I) out.orbit_I[at] = I;
        }
        if (out.states) {
            std::array<double, 4> zz{kNaN, kNaN, kNaN, kNaN};
            if (z)
                zz = *z;
            else
                state(x, y, zz);
            for (int c = 0; c < 4; ++c) out.states[4 * at + c] = zz[std::size_t(c)];
        }
    };
    // The return from x_k of orbit i (k a multiple of every).
    auto record_return = [&](std::int64_t i, std::int64_t k, const FlowStep& st) {
        const std::int64_t at = i * nr + k / every;
        if (out.regions) out.regions[at] = static_cast<std::int8_t>(st.region);
        if (out.times) out.times[at] = st.ret.time;
        if (out.energy_error) out.energy_error[at] = st.ret.energy_error;
        if (out.integrator_steps) out.integrator_steps[at] = st.ret.steps;
        if (out.itinerary) out.itinerary[at] = st.ret.itinerary;
    };
    // An orbit's outputs once it stops, and the NaN / None tails of its recorded arrays. `returns`:
    // the returns recorded or skipped so far (steps, and the exiting one with stop_on_exit).
    auto finish = [&](std::int64_t i, double x, double y, double rot, std::int64_t steps, Status st, int visited,
                      double y_lo, double y_hi, const std::int64_t* res, std::int64_t returns) {
        if (out.visited) out.visited[i] = static_cast<std::int8_t>(visited);
        if (out.x_final) out.x_final[i] = x;
        if (out.y_final) out.y_final[i] = y;
        if (out.rotation) out.rotation[i] = steps > 0 ? rot / double(steps) : kNaN;
        if (out.status) out.status[i] = static_cast<std::int8_t>(st);
        if (out.steps_done) out.steps_done[i] = steps;
        if (out.stop_step && st == Status::Stopped) out.stop_step[i] = steps;
        if (out.y_min) out.y_min[i] = y_lo;
        if (out.y_max) out.y_max[i] = y_hi;
        if (out.residence) std::copy(res, res + kRegionCount, out.residence + i * kRegionCount);
        for (std::int64_t k = steps / every + 1; k < np; ++k) {
            const std::int64_t at = i * np + k;
            if (out.orbit_x) out.orbit_x[at] = kNaN;
            if (out.orbit_y) out.orbit_y[at] = kNaN;
            if (out.orbit_theta) out.orbit_theta[at] = kNaN;
            if (out.orbit_I) out.orbit_I[at] = kNaN;
            if (out.states)
                for (int c = 0; c < 4; ++c) out.states[4 * at + c] = kNaN;
        }
        for (std::int64_t k = (returns + every - 1) / every; k < nr; ++k) {
            const std::int64_t at = i * nr + k;
            if (out.regions) out.regions[at] = static_cast<std::int8_t>(Region::None);
            if (out.times) out.times[at] = kNaN;
            if (out.energy_error) out.energy_error[at] = kNaN;
            if (out.integrator_steps) out.integrator_steps[at] = -1;
            if (out.itinerary) out.itinerary[at] = kNoItinerary;
        }
    };

    const int threads = detail::worker_count(opt.n_threads, n);
    detail::WorkQueue queue(n, detail::balanced_block(n, threads, 4));
    std::mutex mu;
    detail::run_workers(threads, queue, [&](detail::WorkCursor& cur) {
        // Orbits side by side, one per lane of a TracerGroup (8 for stepper "taylor": their Taylor
        // series are expanded together); each lane runs its orbit's returns one after another
        // and takes the next orbit when it ends. An orbit is bit for bit what it is alone.
        const bool tangent = out.tangent.active();
        detail::PooledGroup pooled(pool_.get(), s_, opt_, tangent ? 2 : 0);
        detail::TracerGroup& group = *pooled;
        const int L = group.lanes();
        for (int l = 0; l < L; ++l) {
            group.lane(l).set_labels(opt.labels);
            group.lane(l).set_section_energy(h_);  // an image's chart point is the next start
        }
        detail::ProgressShare progress(opt.progress, 1);
        struct Orbit {
            std::int64_t i = -1;
            double x = 0, y = 0, rot = 0, y_lo = 0, y_hi = 0;
            std::int64_t res[kRegionCount] = {};
            std::int64_t k = 0, returns = 0;
            bool reported = false;
            int visited = 0;
            Status status = Status::Ok;
            detail::DenseRecorder rec;
            TangentProduct tp;                 // record "jacobian"
            Status tangent_status = Status::Ok;  // NonFinite once a return's Jacobian was not
            std::array<double, 2> chart{kNaN, kNaN};  // the last image's section coordinates
            std::array<double, 4> chart_point{};      // and its point of Sigma_h (ReturnResult)
        };
        std::vector<Orbit> lane(static_cast<std::size_t>(L));
        // The end of lane l's orbit: its outputs, its recorded tails, the progress it will not make.
        auto close = [&](Orbit& o) {
            finish(o.i, o.x, o.y, o.rot, o.k, o.status, o.visited, o.y_lo, o.y_hi, o.res, o.returns);
            out.tangent.write(o.i, o.tp, o.tangent_status);
            if (traj.truncated) traj.truncated[o.i] = o.rec.truncated ? 1 : 0;
            // The returns an orbit that stopped early will not take are accounted for (not when
            // cancelled: the count then shows how far the run got).
            if (o.status != Status::Interrupted) progress.add(ns - o.k);
            o.i = -1;
        };
        // Start lane l's next return, or end its orbit (false).
        auto next_return = [&](int l) {
            Orbit& o = lane[std::size_t(l)];
            if (!(o.k < ns && o.status == Status::Ok)) return false;
            if (opt.cancelled()) {
                o.status = Status::Interrupted;
                return false;
            }
            std::array<double, 4> z{};
            FlowStep st;
            if (!advance_start(o.x, o.y, false, z, st, &o.chart, &o.chart_point)) {
                o.status = orbit_status(st.ret.status);
                return false;
            }
            if (tangent) {
                double t0[8];
                start_tangents(o.x, z, to_section(o.x, o.y).second, t0);
                group.start(l, z, false, opt.cancel, t0);
            } else {
                group.start(l, z, false, opt.cancel);
            }
            return true;
        };
        // After lane l's return: the bookkeeping of one iteration (false: the orbit ends here).
        auto after_return = [&](Orbit& o, const FlowStep& st) {
            if (st.ret.status != FlowStatus::Ok) {
                o.status = orbit_status(st.ret.status);
                return false;
            }
            const std::int64_t k = o.k;
            o.rec.offset += st.ret.time;  // the orbit's clock runs on into the next return
            const int r = int(st.region);
            if (r >= 0) {
                o.visited |= 1 << r;
                ++o.res[r];
            }
            o.returns = k + 1;
            if (k % every == 0) record_return(o.i, k, st);
            if (opt.exit_mask && !o.reported && !(r >= 0 && ((opt.exit_mask >> r) & 1u))) {
                if (out.exit_step) out.exit_step[o.i] = k;
                o.reported = true;
                if (opt.stop_on_exit) {  // recorded above, not taken
                    o.status = Status::Exited;
                    return false;
                }
            }
            if (out.rotation) o.rot += rotation_of(o.x, o.y, st.region, st.x);
            if (tangent) {
                double J[4];
                end_jacobian(st, J);
                if (std::isfinite(J[0]) && std::isfinite(J[1]) && std::isfinite(J[2]) && std::isfinite(J[3]))
                    o.tp.multiply(J);
                else if (o.tangent_status == Status::Ok)
                    o.tangent_status = Status::NonFinite;
            }
            o.x = st.x;
            o.y = st.y;
            o.chart = st.ret.chart;
            o.chart_point = st.ret.chart_point;
            o.y_lo = std::min(o.y_lo, o.y);
            o.y_hi = std::max(o.y_hi, o.y);
            if ((k + 1) % every == 0) record_point(o.i, k + 1, o.x, o.y, nullptr);
            progress.add(1);
            if (stop.active() && stop.reached(o.x, o.y)) o.status = Status::Stopped;
            ++o.k;
            return true;
        };
        // Lane l takes orbits until one has a return to trace.
        auto open = [&](int l) {
            Orbit& o = lane[std::size_t(l)];
            for (std::int64_t i; cur.pop(i);) {
                o.i = i;
                o.x = x0[i];
                o.y = o.y_lo = o.y_hi = y0[i];
                o.rot = 0;
                std::fill(o.res, o.res + kRegionCount, std::int64_t(0));
                o.k = o.returns = 0;
                o.reported = false;
                o.visited = 0;
                o.status = Status::Ok;
                o.tp = TangentProduct{};
                o.tangent_status = Status::Ok;
                if (out.exit_step) out.exit_step[i] = -1;
                if (out.stop_step) out.stop_step[i] = -1;
                if (traj.truncated) traj.truncated[i] = 0;
                std::array<double, 4> z{};
                if (!state(o.x, o.y, z)) {
                    record_point(i, 0, o.x, o.y, nullptr);
                    finish(i, o.x, o.y, 0.0, 0, Status::OffSection, 0, o.y_lo, o.y_hi, o.res, 0);
                    out.tangent.write(i, TangentProduct{}, Status::Ok);
                    progress.add(ns);
                    o.i = -1;
                    continue;
                }
                o.rec = detail::DenseRecorder{};
                if (traj.active()) {
                    o.rec.start(&traj.points[i], &traj.kinds[i], traj.dt, traj.max_points_per_orbit);
                    group.lane(l).set_dense(&o.rec);
                }
                record_point(i, 0, o.x, o.y, &z);
                // The start counts: an orbit that starts in the set stops there, having taken no return.
                if (stop.active() && stop.reached(wrap(o.x), o.y)) o.status = Status::Stopped;
                if (next_return(l)) return;
                close(o);
            }
        };
        for (int l = 0; l < L; ++l) open(l);
        while (group.any_busy()) {
            const unsigned over = group.step(opt.cancel);
            for (int l = 0; l < L; ++l) {
                if (!((over >> l) & 1u)) continue;
                Orbit& o = lane[std::size_t(l)];
                if (after_return(o, advance_end(group.collect(l), false)) && next_return(l)) continue;
                close(o);
                open(l);
            }
        }
        if (out.work) {
            const FlowWork w = pooled.work();
            std::lock_guard<std::mutex> lock(mu);
            *out.work += w;
        }
    });
}

}  // namespace hovering
