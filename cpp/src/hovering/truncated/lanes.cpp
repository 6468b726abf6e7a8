// The SIMD lane kernel of the truncated family: Eigen packets + SLEEF sin. One source, compiled
// once with the core's flags and, in the portable x86-64 build, once more per wider instruction
// set (AVX2, AVX-512) with HOVERING_LANES_NS naming the build's namespace and HOVERING_LANES_TABLE
// its table; iterate.cpp runs the table the dispatch selects (detail/simd_dispatch.hpp). Compiled
// with -fno-trapping-math -fno-math-errno (see CMakeLists.txt): without them GCC will not if-convert Eigen's select()
// chains or inline sqrt, and the kernel falls back to scalar code. Neither changes IEEE results.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "hovering/detail/common.hpp"
#include "hovering/detail/parallel.hpp"
#include "hovering/detail/simd.hpp"
#include "hovering/detail/simd_level.hpp"
#include "hovering/truncated/lanes.hpp"
#include "hovering/truncated/map.hpp"

#ifndef HOVERING_LANES_NS
#define HOVERING_LANES_NS lanes_base
#define HOVERING_LANES_TABLE hovering_lanes_base
#endif

namespace hovering::HOVERING_LANES_NS {

namespace {

using detail::Finisher;
using detail::kInvTwoPi;
using detail::kNaN;
using detail::kPi;
using detail::kTwoPi;
using detail::kW;
using detail::Packet;
using detail::pcos;
using detail::psin;
using detail::Tally;
using detail::WorkCursor;
namespace ei = Eigen::internal;

// Arc lengths of a packet of heights: packet arithmetic for the analytic model, in the same
// operation order as AnalyticArcs::at so that both kernels round alike ...
inline void arcs_packet(const AnalyticArcs& a, const Packet& k, Packet& Om, Packet& JR, Packet& J1) {
    const Packet zero = ei::pset1<Packet>(0.0);
    Om = ei::padd(ei::pset1<Packet>(a.Omega0), ei::pmul(ei::pset1<Packet>(a.tau0), k));
    J1 = ei::pmul(ei::pset1<Packet>(2.0 * a.lam), detail::psqrt_rn(ei::pmax(ei::pnegate(k), zero)));
    JR = ei::pand(ei::pcmp_lt(k, zero),
                  ei::padd(ei::pset1<Packet>(2.0 * (kPi - a.theta_w)), ei::pmul(ei::pset1<Packet>(a.tau1), k)));
}

// ... and lane by lane for tables (spline lookups are gathers; this model is not the hot path).
inline void arcs_packet(const TabulatedArcs& a, const Packet& k, Packet& Om, Packet& JR, Packet& J1) {
    alignas(64) double kk[kW], o[kW], r[kW], l[kW];
    ei::pstore(kk, k);
    for (int w = 0; w < kW; ++w) {
        const ArcLengths x = a.at(kk[w]);
        o[w] = x.Omega;
        r[w] = x.JR;
        l[w] = x.J1;
    }
    Om = ei::pload<Packet>(o);
    JR = ei::pload<Packet>(r);
    J1 = ei::pload<Packet>(l);
}

template <bool Fast>
inline Packet force_packet(const SineForcing&, const Packet& p) {
    return psin<Fast>(p);
}

// d omega_a / dK of each lane's arc (record "jacobian"): Omega' plus |J_R|' on J_1, minus |J_1|' on
// J_R (up, rt: the lanes in J_1, J_R; both masks are 0 for K >= 0, so what the K >= 0 lanes compute
// for the arcs' slopes, -lam / 0 or NaN, is masked away).
inline Packet slope_packet(const AnalyticArcs& a, const Packet& k, const Packet& up, const Packet& rt) {
    const Packet sJ1 = ei::pdiv(ei::pset1<Packet>(-a.lam), detail::psqrt_rn(ei::pnegate(k)));
    return ei::psub(ei::padd(ei::pset1<Packet>(a.tau0), ei::pand(up, ei::pset1<Packet>(a.tau1))), ei::pand(rt, sJ1));
}

inline Packet slope_packet(const TabulatedArcs& a, const Packet& k, const Packet& up, const Packet& rt) {
    alignas(64) double kk[kW], w[kW], mu[kW], mr[kW];
    ei::pstore(kk, k);
    ei::pstore(mu, up);
    ei::pstore(mr, rt);
    auto set = [](double mask) {  // a lane mask is all ones or all zeros
        std::uint64_t b;
        std::memcpy(&b, &mask, 8);
        return b != 0;
    };
    for (int l = 0; l < kW; ++l) {
        const ArcSlopes d = a.slopes(kk[l]);
        w[l] = d.Omega;
        if (set(mu[l])) w[l] += d.JR;
        if (set(mr[l])) w[l] -= d.J1;
    }
    return ei::pload<Packet>(w);
}

template <bool Fast>
inline Packet force_slope_packet(const SineForcing&, const Packet& p) {
    return pcos<Fast>(p);
}

template <bool Fast>
inline Packet force_slope_packet(const FourierForcing& f, const Packet& p) {
    Packet acc = ei::pset1<Packet>(0.0);
    for (std::size_t k = 0; k < f.b.size(); ++k)
        if (f.b[k] != 0.0)
            acc = ei::padd(acc, ei::pmul(ei::pset1<Packet>(double(k + 1) * f.b[k]),
                                         pcos<Fast>(ei::pmul(ei::pset1<Packet>(double(k + 1)), p))));
    return acc;
}

template <bool Fast>
inline Packet force_packet(const FourierForcing& f, const Packet& p) {
    Packet acc = ei::pset1<Packet>(0.0);
    for (std::size_t k = 0; k < f.b.size(); ++k)
        if (f.b[k] != 0.0)
            acc = ei::padd(
                acc, ei::pmul(ei::pset1<Packet>(f.b[k]), psin<Fast>(ei::pmul(ei::pset1<Packet>(double(k + 1)), p))));
    return acc;
}

// Packets in flight per worker: several independent dependency chains hide the latency of one
// step (sqrt, floor, sin) while the whole state stays in registers / L1.
constexpr int kP = 8;

// How close to an arc end the offset of phi from phi_01 must come for a packet to be classified
// by comparing with the arc starts. The offset's rounding (phi - phi_01, its reduction mod 2 pi and
// the starts' own) is a few ulps of |phi_01| + 2 pi < 2^20, as |Omega| <= 1e6 on the band, so
// below 1e-9; 2^-24 = 6e-8 keeps that by a factor of 60, and only ~1 lane-step in 1e7 is that close.
constexpr double kNearArcEnd = 0x1p-24;
constexpr int kLanes = kP * kW;

template <bool Fast, class A, class F>
void run_simd(const MapCore<A, F>& m, const double* phi0, const double* K0, WorkCursor& src, const IterateOptions& opt,
              const IterateOutput& out, detail::ProgressShare& progress) {
    // Lane kernel on Eigen packets: kLanes orbits are stepped together; an orbit that stops frees
    // its lane, which is refilled from the source at once, so the vectors stay full even when
    // orbits stop at very different times (early exit). Per-lane bookkeeping happens on a rare
    // path that unpacks the packets into lane arrays and packs them back.
    const Finisher finish(opt, out, progress);
    const std::int64_t ns = opt.n_steps, every = opt.every;
    const double lo = m.band().lo, hi = m.band().hi;
    const bool watch = opt.exit_mask != 0;
    const bool need_reg = watch || out.regions || out.visited;  // region codes are only built when read
    const bool extrema = out.K_min || out.K_max, residence = out.residence != nullptr;
    const bool rec_states = out.orbit_phi || out.orbit_K, rec = rec_states || out.regions;
    const bool tangent = out.tangent.active();
    const StopCondition& stop = opt.stop;
    const bool stopping = stop.active(), above = stop.side == StopSide::Above;
    const Curve* curve = stopping ? stop.curve.get() : nullptr;
    const bool flat = stopping && curve->is_constant();
    const Packet zero = ei::pset1<Packet>(0.0), one = ei::pset1<Packet>(1.0), two = ei::pset1<Packet>(2.0),
                 three = ei::pset1<Packet>(3.0), pi = ei::pset1<Packet>(kPi), mpi = ei::pset1<Packet>(-kPi),
                 twopi = ei::pset1<Packet>(kTwoPi), inv2pi = ei::pset1<Packet>(kInvTwoPi),
                 half = ei::pset1<Packet>(0.5), eps = ei::pset1<Packet>(m.eps()), plo = ei::pset1<Packet>(lo),
                 phi_ = ei::pset1<Packet>(hi), all = ei::pcmp_eq(zero, zero), margin = ei::pset1<Packet>(kNearArcEnd),
                 pi_less_margin = ei::pset1<Packet>(kPi - kNearArcEnd);
    // The stop curve: its scale and cell count, and the bound beyond which no state can be in the set.
    const Packet cscale = ei::pset1<Packet>(stopping ? curve->scale() : 0.0),
                 ncells = ei::pset1<Packet>(stopping ? double(curve->size()) : 0.0),
                 cflat = ei::pset1<Packet>(stopping ? curve->samples()[0] : 0.0),
                 cbound = ei::pset1<Packet>(!stopping ? 0.0
                                            : above   ? curve->lower()
                                                      : curve->upper());
    // detail::wrap and detail::wrap_once on packets (same operations, same order).
    auto pwrap = [&](const Packet& x) {
        Packet y = ei::psub(x, ei::pmul(twopi, ei::pfloor(ei::pmul(ei::padd(x, pi), inv2pi))));
        y = ei::pselect(ei::pcmp_le(pi, y), ei::psub(y, twopi), y);
        return ei::pselect(ei::pcmp_lt(y, mpi), ei::padd(y, twopi), y);
    };
    auto wrap_once = [&](const Packet& u) { return ei::pselect(ei::pcmp_le(pi, u), ei::psub(u, twopi), u); };
    // Curve::value on packets (same operations, same order).
    auto curve_at = [&](const Packet& p) {
        if (flat) return cflat;
        const Packet t = ei::pmul(ei::padd(p, pi), cscale);
        Packet f = ei::pfloor(t);
        const Packet s = ei::psub(t, f);
        f = ei::pselect(ei::pcmp_le(ncells, f), ei::psub(f, ncells), f);
        Packet c[4];
        detail::pgather_cells(curve->cells(), f, c);
        return ei::padd(c[0], ei::pmul(s, ei::padd(c[1], ei::pmul(s, ei::padd(c[2], ei::pmul(s, c[3]))))));
    };
    auto in_set = [&](const Packet& p, const Packet& k) {
        const Packet c = curve_at(p);
        return above ? ei::pcmp_le(c, k) : ei::pcmp_le(k, c);
    };
    Packet allow[4];
    for (int r = 0; r < 4; ++r) allow[r] = (opt.exit_mask >> r) & 1u ? all : zero;

    Packet phi[kP], K[kP], rot[kP], live[kP], fresh[kP], reg[kP], omega[kP];
    Packet kmin[kP], kmax[kP], nup[kP], nright[kP], nbelow[kP], mup[kP], mright[kP], mbelow[kP];
    alignas(64) double lphi[kLanes], lK[kLanes], lrot[kLanes], llive[kLanes], lfresh[kLanes], lreg[kLanes];
    alignas(64) double lkmin[kLanes], lkmax[kLanes], lup[kLanes], lright[kLanes], lbelow[kLanes];
    // Regions visited (record "visited" only): one all-ones mask per region code 0..3 and lane.
    Packet seen[4][kP];
    alignas(64) double lseen[4][kLanes];
    // Record "jacobian": each lane's tangent product (TangentProduct: c, s, L1, L2, u), whether it
    // took a step from an arc start, and the slope d omega_a / dK of the current step's arc.
    Packet tc[kP], ts[kP], tl1[kP], tl2[kP], tu[kP], tcor[kP], wsl[kP];
    alignas(64) double ltc[kLanes], lts[kLanes], ltl1[kLanes], ltl2[kLanes], ltu[kLanes], ltcor[kLanes];
    const Packet code[4] = {zero, one, two, three};
    std::int64_t idx[kLanes], start[kLanes], due[kLanes];  // due: the next n whose state / return is recorded
    std::int64_t slot[kLanes];  // due / every: where that record goes in the orbit's row
    bool busy[kLanes];          // the lane holds an orbit (llive without an unpack)
    // Recorded states and regions wait here, one row per iteration (kLanes wide), and are written
    // kBlock at a time as one run per orbit: a per-iteration write unpacked every packet and
    // divided twice per lane (4x the map's own time at every = 1). Flushed before any lane
    // changes hands, so every buffered row belongs to the lane's current orbit.
    constexpr int kBlock = 32;
    alignas(64) double bphi[kBlock][kLanes], bK[kBlock][kLanes], breg[kBlock][kLanes];
    int bfill = 0;  // rows buffered: iterations it - bfill .. it - 1
    std::int64_t it = 0;  // iterations of this worker; lane j has taken it - start[j] steps

    auto unpack = [&] {
        for (int q = 0; q < kP; ++q) {
            ei::pstore(lphi + q * kW, phi[q]);
            ei::pstore(lK + q * kW, K[q]);
            ei::pstore(lrot + q * kW, rot[q]);
            ei::pstore(llive + q * kW, live[q]);
            ei::pstore(lfresh + q * kW, fresh[q]);
            if (out.visited)
                for (int r = 0; r < 4; ++r) ei::pstore(lseen[r] + q * kW, seen[r][q]);
            if (extrema) {
                ei::pstore(lkmin + q * kW, kmin[q]);
                ei::pstore(lkmax + q * kW, kmax[q]);
            }
            if (residence) {
                ei::pstore(lup + q * kW, nup[q]);
                ei::pstore(lright + q * kW, nright[q]);
                ei::pstore(lbelow + q * kW, nbelow[q]);
            }
            if (tangent) {
                ei::pstore(ltc + q * kW, tc[q]);
                ei::pstore(lts + q * kW, ts[q]);
                ei::pstore(ltl1 + q * kW, tl1[q]);
                ei::pstore(ltl2 + q * kW, tl2[q]);
                ei::pstore(ltu + q * kW, tu[q]);
                ei::pstore(ltcor + q * kW, tcor[q]);
            }
        }
    };
    auto pack = [&] {
        for (int q = 0; q < kP; ++q) {
            phi[q] = ei::pload<Packet>(lphi + q * kW);
            K[q] = ei::pload<Packet>(lK + q * kW);
            rot[q] = ei::pload<Packet>(lrot + q * kW);
            live[q] = ei::pload<Packet>(llive + q * kW);
            fresh[q] = ei::pload<Packet>(lfresh + q * kW);
            if (out.visited)
                for (int r = 0; r < 4; ++r) seen[r][q] = ei::pload<Packet>(lseen[r] + q * kW);
            if (extrema) {
                kmin[q] = ei::pload<Packet>(lkmin + q * kW);
                kmax[q] = ei::pload<Packet>(lkmax + q * kW);
            }
            if (residence) {
                nup[q] = ei::pload<Packet>(lup + q * kW);
                nright[q] = ei::pload<Packet>(lright + q * kW);
                nbelow[q] = ei::pload<Packet>(lbelow + q * kW);
            }
            if (tangent) {
                tc[q] = ei::pload<Packet>(ltc + q * kW);
                ts[q] = ei::pload<Packet>(lts + q * kW);
                tl1[q] = ei::pload<Packet>(ltl1 + q * kW);
                tl2[q] = ei::pload<Packet>(ltl2 + q * kW);
                tu[q] = ei::pload<Packet>(ltu + q * kW);
                tcor[q] = ei::pload<Packet>(ltcor + q * kW);
            }
        }
    };
    const double on = [] {
        double x;
        const std::uint64_t b = ~std::uint64_t(0);
        std::memcpy(&x, &b, 8);
        return x;
    }();
    auto is_live = [&](int j) { return std::memcmp(&llive[j], &on, 8) == 0; };
    // Lane j's tally from the lane arrays (after unpack()); `exiting`: the exiting return is counted.
    auto tally = [&](int j, bool exiting = false) {
        Tally t;
        t.rot = lrot[j];
        if (out.visited)
            for (int r = 0; r < 4; ++r) t.visited |= std::memcmp(&lseen[r][j], &on, 8) == 0 ? 1 << r : 0;
        t.K_min = lkmin[j];
        t.K_max = lkmax[j];
        t.upper = lup[j];
        t.right = lright[j];
        t.below = lbelow[j];
        t.counted = it - start[j] + (exiting ? 1 : 0);
        if (tangent) {
            t.tangent = TangentProduct{ltc[j], lts[j], ltl1[j], ltl2[j], ltu[j], it - start[j]};
            if (std::memcmp(&ltcor[j], &on, 8) == 0) t.tangent_status = Status::Corner;
        }
        return t;
    };
    auto clear = [&](int j) {
        lrot[j] = 0.0;
        for (int r = 0; r < 4; ++r) lseen[r][j] = 0.0;
        lup[j] = lright[j] = lbelow[j] = 0.0;
        ltc[j] = 1.0;
        lts[j] = ltl1[j] = ltl2[j] = ltu[j] = ltcor[j] = 0.0;
    };
    // Put the next orbit that starts inside the band and outside the stop set into lane j (the
    // others finish at once); with no work left the lane computes a harmless point that is ignored.
    auto fill = [&](int j) {
        for (std::int64_t i; src.pop(i);) {
            const double w = detail::wrap(phi0[i]);  // the kernel compares angles in [-pi, pi)
            finish.start(i, w, K0[i]);
            Tally t0;
            t0.K_min = t0.K_max = K0[i];
            if (!(K0[i] > lo && K0[i] < hi)) {
                finish(i, w, K0[i], 0, Status::Escaped, t0);
                continue;
            }
            if (stopping && stop.reached(w, K0[i])) {
                finish(i, w, K0[i], 0, Status::Stopped, t0);
                continue;
            }
            if (ns == 0) {
                finish(i, w, K0[i], 0, Status::Ok, t0);
                continue;
            }
            lphi[j] = w;
            lK[j] = K0[i];
            llive[j] = on;
            lfresh[j] = on;  // not yet reported as leaving the watched regions
            lkmin[j] = lkmax[j] = K0[i];
            clear(j);
            idx[j] = i;
            start[j] = it;
            due[j] = 0;
            slot[j] = 0;
            busy[j] = true;
            return true;
        }
        lphi[j] = 0.0;
        lK[j] = 0.0;
        llive[j] = 0.0;
        lfresh[j] = 0.0;
        lkmin[j] = lkmax[j] = 0.0;
        clear(j);
        due[j] = 0;
        slot[j] = 0;
        busy[j] = false;
        return false;
    };
    int nlive = 0;
    for (int j = 0; j < kLanes; ++j) nlive += fill(j);
    pack();
    auto next_completion = [&] {
        std::int64_t c = ns;
        for (int j = 0; j < kLanes; ++j)
            if (is_live(j)) c = std::min(c, ns - (it - start[j]));
        return c;
    };
    // Write the buffered rows: lane j records x_n (and the region of its return) for n = due[j],
    // due[j] + every, ..., which sit at rows start[j] + n - (it - bfill).
    auto flush = [&] {
        const std::int64_t base = it - bfill, e = every;
        const int nb = bfill;
        for (int j = 0; j < kLanes; ++j) {
            if (!busy[j]) continue;
            double* __restrict op = out.orbit_phi ? out.orbit_phi + idx[j] * finish.n_states : nullptr;
            double* __restrict oK = out.orbit_K ? out.orbit_K + idx[j] * finish.n_states : nullptr;
            std::int8_t* __restrict orr = out.regions ? out.regions + idx[j] * finish.n_returns : nullptr;
            std::int64_t r = start[j] + due[j] - base, sl = slot[j];
            if (e == 1) {  // one tight copy per array (the common case)
                const std::int64_t n = nb - r;
                if (op)
                    for (std::int64_t k = 0; k < n; ++k) op[sl + k] = bphi[r + k][j];
                if (oK)
                    for (std::int64_t k = 0; k < n; ++k) oK[sl + k] = bK[r + k][j];
                if (orr)
                    for (std::int64_t k = 0; k < n; ++k) orr[sl + k] = static_cast<std::int8_t>(breg[r + k][j]);
                sl += n;
                // The next flush writes the next kBlock records of this orbit: ask for their lines
                // now (a fresh output array misses each one, and one miss at a time stalled the copy).
                for (int k = 0; k < kBlock; k += 8) {
                    if (op) __builtin_prefetch(op + sl + k, 1);
                    if (oK) __builtin_prefetch(oK + sl + k, 1);
                }
                if (orr) __builtin_prefetch(orr + sl, 1);
            } else {
                for (; r < nb; r += e, ++sl) {
                    if (op) op[sl] = bphi[r][j];
                    if (oK) oK[sl] = bK[r][j];
                    if (orr) orr[sl] = static_cast<std::int8_t>(breg[r][j]);
                }
            }
            slot[j] = sl;
            due[j] = sl * e;
        }
        bfill = 0;
    };
    std::int64_t countdown = next_completion();

    while (nlive > 0) {
        if ((it & 63) == 0 && opt.cancelled()) {
            if (rec) flush();
            unpack();
            for (int j = 0; j < kLanes; ++j)
                if (is_live(j)) finish(idx[j], lphi[j], lK[j], it - start[j], Status::Interrupted, tally(j));
            for (std::int64_t i; src.pop(i);) {  // not started: keep their initial state
                const double w = detail::wrap(phi0[i]);
                finish.start(i, w, K0[i]);
                const bool inside = K0[i] > lo && K0[i] < hi;
                Tally t0;
                t0.K_min = t0.K_max = K0[i];
                finish(i, w, K0[i], 0, inside ? Status::Interrupted : Status::Escaped, t0);
            }
            return;
        }
        // Classify every lane: region code and rotation omega_a, exactly as detail::classify, which
        // compares phi with the arc starts (the boundary convention). That costs ~25 vector
        // operations per packet, so a first pass uses the offset d of phi from phi_01 reduced mod
        // 2 pi, which gives the same regions wherever it is farther than kNearArcEnd from an arc
        // end (d = 0, |J_1|, |J_1| + |J_R|, 2 pi); only if some lane is that close (~1 lane-step in
        // 1e7) are all packets classified again by comparison with the starts.
        auto classify_packets = [&](auto exact) {  // std::bool_constant: two instantiations
            Packet near = zero;
            for (int q = 0; q < kP; ++q) {
                Packet Om, JR, J1;
                arcs_packet(m.arcs(), K[q], Om, JR, J1);
                const Packet p01 = ei::psub(pi, ei::pmul(half, ei::padd(ei::padd(Om, JR), J1)));
                const Packet neg = ei::pcmp_lt(K[q], zero);
                Packet in1, inR;  // phi in J_1; phi in J_R (fast pass: in J_1 or J_R)
                if constexpr (!decltype(exact)::value) {
                    Packet d = ei::psub(phi[q], p01);
                    d = ei::psub(d, ei::pmul(twopi, ei::pfloor(ei::pmul(d, inv2pi))));
                    const Packet T = ei::padd(J1, JR);
                    in1 = ei::pcmp_lt(d, J1);
                    inR = ei::pcmp_lt(d, T);
                    const Packet close =
                        ei::por(ei::pcmp_lt(ei::pmin(ei::pabs(ei::psub(d, J1)), ei::pabs(ei::psub(d, T))), margin),
                                ei::pcmp_lt(pi_less_margin, ei::pabs(ei::psub(d, pi))));
                    near = ei::por(near, ei::pand(close, neg));
                } else {
                    const Packet s1 = pwrap(p01);
                    const Packet uR = ei::padd(s1, J1);
                    const Packet sR = wrap_once(uR), s0 = wrap_once(ei::padd(uR, JR));
                    // detail::in_arc(x, a, b) as masks: (a <= x) ^ (x < b) ^ (a <= b). For a <= b
                    // the first two are never both false (x < a <= b), so the xor is their and;
                    // for a > b never both true, so it is their or. Both arcs compare with s_R.
                    const Packet below_R = ei::pcmp_lt(phi[q], sR);
                    in1 = ei::pxor(ei::pxor(ei::pcmp_le(s1, phi[q]), below_R), ei::pcmp_le(s1, sR));
                    inR = ei::pxor(ei::pandnot(all, below_R), ei::pxor(ei::pcmp_lt(phi[q], s0), ei::pcmp_le(sR, s0)));
                }
                const Packet up = ei::pand(neg, in1);
                const Packet rt = ei::pandnot(ei::pand(neg, inR), up);
                omega[q] = ei::psub(ei::padd(Om, ei::pand(up, JR)), ei::pand(rt, J1));
                if (tangent) {
                    wsl[q] = slope_packet(m.arcs(), K[q], up, rt);
                    if constexpr (decltype(exact)::value) {
                        // A step from an arc start exactly: the derivative is one-sided there (only
                        // this pass can see it: the fast pass sends every lane near an arc end here).
                        const Packet s1 = pwrap(p01);
                        const Packet uR = ei::padd(s1, J1);
                        const Packet sR = wrap_once(uR), s0 = wrap_once(ei::padd(uR, JR));
                        const Packet at = ei::por(ei::por(ei::pcmp_eq(phi[q], s1), ei::pcmp_eq(phi[q], sR)),
                                                  ei::pcmp_eq(phi[q], s0));
                        tcor[q] = ei::por(tcor[q], ei::pand(live[q], ei::pand(neg, at)));
                    }
                }
                if (need_reg) reg[q] = ei::pselect(neg, ei::pselect(up, two, ei::pselect(rt, three, one)), zero);
                if (residence) {
                    mup[q] = up;
                    mright[q] = rt;
                    mbelow[q] = neg;
                }
            }
            return ei::predux_any(near);
        };
        if (classify_packets(std::false_type{})) classify_packets(std::true_type{});
        Packet leaving = zero;
        if (need_reg)
            for (int q = 0; q < kP; ++q) {
                if (out.visited)
                    for (int r = 0; r < 4; ++r)
                        seen[r][q] = ei::por(seen[r][q], ei::pand(live[q], ei::pcmp_eq(reg[q], code[r])));
                if (watch) {
                    const Packet ok =
                        ei::pselect(ei::pcmp_eq(reg[q], zero), allow[0],
                                    ei::pselect(ei::pcmp_eq(reg[q], one), allow[1],
                                                ei::pselect(ei::pcmp_eq(reg[q], two), allow[2], allow[3])));
                    leaving = ei::por(leaving, ei::pandnot(ei::pand(live[q], fresh[q]), ok));
                }
            }
        if (watch && ei::predux_any(leaving)) {
            if (rec) flush();
            unpack();
            for (int q = 0; q < kP; ++q) ei::pstore(lreg + q * kW, reg[q]);
            bool refilled = false;
            for (int j = 0; j < kLanes; ++j) {
                if (!is_live(j) || std::memcmp(&lfresh[j], &on, 8) != 0) continue;
                const int r = int(lreg[j]);
                if ((opt.exit_mask >> r) & 1u) continue;
                const std::int64_t n = it - start[j];
                if (out.exit_step) out.exit_step[idx[j]] = n;
                lfresh[j] = 0.0;
                if (opt.stop_on_exit) {
                    // The exiting return is recorded (its region, its residence count), not taken.
                    if (n % every == 0) finish.region(idx[j], n, r);
                    lbelow[j] += r != int(Region::Beside);
                    lup[j] += r == int(Region::Upper);
                    lright[j] += r == int(Region::Right);
                    finish(idx[j], lphi[j], lK[j], n, Status::Exited, tally(j, true));
                    nlive -= !fill(j);
                    refilled = true;
                }
            }
            pack();
            if (refilled) {  // refilled lanes need their own classification
                countdown = next_completion();
                continue;
            }
        }
        if (rec) {  // every lane's state x_n and the region of its return, into the buffer
            if (bfill == kBlock) flush();  // (rows it - kBlock .. it - 1)
            for (int q = 0; q < kP; ++q) {
                if (rec_states) {
                    ei::pstore(bphi[bfill] + q * kW, phi[q]);
                    ei::pstore(bK[bfill] + q * kW, K[q]);
                }
                if (out.regions) ei::pstore(breg[bfill] + q * kW, reg[q]);  // reg is built when read
            }
            ++bfill;
        }
        if (residence)
            for (int q = 0; q < kP; ++q) {
                nup[q] = ei::padd(nup[q], ei::pand(mup[q], one));
                nright[q] = ei::padd(nright[q], ei::pand(mright[q], one));
                nbelow[q] = ei::padd(nbelow[q], ei::pand(mbelow[q], one));
            }
        // Step: rotate, wrap to [-pi, pi), kick.
        Packet outside = zero;
        for (int q = 0; q < kP; ++q) {
            rot[q] = ei::padd(rot[q], omega[q]);
            const Packet p = pwrap(ei::padd(phi[q], omega[q]));
            phi[q] = p;
            K[q] = ei::padd(K[q], ei::pmul(eps, force_packet<Fast>(m.forcing(), p)));
            if (tangent) {
                // TangentProduct::multiply on packets, J = [[1, w], [g, 1 + g w]].
                const Packet w = wsl[q], g = ei::pmul(eps, force_slope_packet<Fast>(m.forcing(), p));
                const Packet d = ei::padd(one, ei::pmul(g, w));
                const Packet x1 = ei::padd(tc[q], ei::pmul(w, ts[q])), y1 = ei::padd(ei::pmul(g, tc[q]), ei::pmul(d, ts[q]));
                const Packet x2 = ei::psub(ei::pmul(w, tc[q]), ts[q]), y2 = ei::psub(ei::pmul(d, tc[q]), ei::pmul(g, ts[q]));
                const Packet r11 = detail::psqrt_rn(ei::padd(ei::pmul(x1, x1), ei::pmul(y1, y1)));
                const Packet cn = ei::pdiv(x1, r11), sn = ei::pdiv(y1, r11);
                const Packet r12 = ei::padd(ei::pmul(cn, x2), ei::pmul(sn, y2));
                const Packet r22 = ei::psub(ei::pmul(cn, y2), ei::pmul(sn, x2));
                tu[q] = ei::padd(tu[q], ei::pmul(ei::pdiv(r12, r11), detail::pexp_u10(ei::psub(tl2[q], tl1[q]))));
                tl1[q] = ei::padd(tl1[q], detail::plog_u10(r11));
                tl2[q] = ei::padd(tl2[q], detail::plog_u10(ei::pabs(r22)));
                tc[q] = cn;
                ts[q] = sn;
            }
            const Packet inside = ei::pand(ei::pcmp_lt(plo, K[q]), ei::pcmp_lt(K[q], phi_));
            outside = ei::por(outside, ei::pandnot(live[q], inside));
            if (extrema) {
                kmin[q] = ei::pmin(kmin[q], K[q]);
                kmax[q] = ei::pmax(kmax[q], K[q]);
            }
        }
        // Stop condition: only packets with a lane beyond the curve's bound can hold a state in the
        // set; which lanes are is decided on the rare path by Curve::value itself (the same bits).
        Packet hit = zero;
        if (stopping) {
            Packet maybe = zero;
            for (int q = 0; q < kP; ++q)
                maybe =
                    ei::por(maybe, ei::pand(live[q], above ? ei::pcmp_le(cbound, K[q]) : ei::pcmp_le(K[q], cbound)));
            if (ei::predux_any(maybe))
                for (int q = 0; q < kP; ++q) hit = ei::por(hit, ei::pand(live[q], in_set(phi[q], K[q])));
        }
        ++it;
        --countdown;
        progress.add(nlive);  // every live lane took one step
        if (countdown == 0 || ei::predux_any(outside) || ei::predux_any(hit)) {
            if (rec) flush();
            unpack();
            for (int j = 0; j < kLanes; ++j) {
                if (!is_live(j)) continue;
                const std::int64_t n = it - start[j];
                if (!(lK[j] > lo && lK[j] < hi))
                    finish(idx[j], lphi[j], lK[j], n, Status::Escaped, tally(j));
                else if (stopping && stop.reached(lphi[j], lK[j]))
                    finish(idx[j], lphi[j], lK[j], n, Status::Stopped, tally(j));
                else if (n == ns)
                    finish(idx[j], lphi[j], lK[j], ns, Status::Ok, tally(j));
                else
                    continue;
                nlive -= !fill(j);
            }
            pack();
            countdown = next_completion();
        }
    }
}

}  // namespace

}  // namespace hovering::HOVERING_LANES_NS

extern "C" const hovering::detail::LaneKernels HOVERING_LANES_TABLE = {
    hovering::detail::kSimdLevel,  // the instruction set Eigen vectorises this build for
    hovering::detail::kW,
    hovering::HOVERING_LANES_NS::kLanes,
    {&hovering::HOVERING_LANES_NS::run_simd<false, hovering::AnalyticArcs, hovering::SineForcing>,
     &hovering::HOVERING_LANES_NS::run_simd<true, hovering::AnalyticArcs, hovering::SineForcing>},
    {&hovering::HOVERING_LANES_NS::run_simd<false, hovering::TabulatedArcs, hovering::FourierForcing>,
     &hovering::HOVERING_LANES_NS::run_simd<true, hovering::TabulatedArcs, hovering::FourierForcing>},
};
