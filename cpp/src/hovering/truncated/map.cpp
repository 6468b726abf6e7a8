// MapCore: construction and validation, single forward and backward steps, arcs on a circle.

#include "hovering/truncated/map.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/truncated/classify.hpp"

namespace hovering {

using detail::bad;
using detail::Classified;
using detail::classify;
using detail::fmt;
using detail::kInf;
using detail::kPi;
using detail::kTwoPi;
using detail::require_angle;
using detail::require_finite;

// ---------------------------------------------------------------------------------------------
// MapCore

namespace {
// The band ends where the rotation |Omega(K)| reaches kMaxAngle = 1e6 rad, a bound set by what phi
// keeps: one step rounds phi + omega (ulp(1e6) / 2 = 5.8e-11 rad there), the 2 pi n the wrap
// subtracts (the same) and uses fl(2 pi), off by n 2.4e-16 < 4e-11: < 2e-10 rad per step, against
// 4e-16 for |Omega| ~ 1. Each decade of rotation beyond costs a decade of phi; at |Omega| = 1e16
// none is left (K = 1e16 stepped to phi = 0.0; Omega0 = -2.4e39 iterated to phi = 3e23 "OK").
// The whole API shares it: Omega0 or a tabulated Omega beyond it is refused, a point beyond it is
// outside the band (step and step_inverse raise, iterate reports ESCAPED).
double arcs_kmax(const AnalyticArcs& a) {
    if (a.tau0 > 0) return (detail::kMaxAngle - a.Omega0) / a.tau0;
    if (a.tau0 < 0) return (detail::kMaxAngle + a.Omega0) / -a.tau0;
    return kInf;
}
double arcs_kmin(const AnalyticArcs& a) {
    if (a.tau0 > 0) return -(detail::kMaxAngle + a.Omega0) / a.tau0;
    if (a.tau0 < 0) return -(detail::kMaxAngle - a.Omega0) / -a.tau0;
    return -kInf;
}
double arcs_kmin(const TabulatedArcs& a) {
    return a.omega_limit(-1.0);
}
double arcs_kmax(const TabulatedArcs& a) {
    return std::min(a.kmax(), a.omega_limit(1.0));
}
void validate_arcs(const AnalyticArcs& a) {
    a.validate();
}
void validate_arcs(const TabulatedArcs&) {}
void validate_forcing(const SineForcing&) {}
void validate_forcing(const FourierForcing& f) {
    if (f.b.empty()) bad("forcing needs at least one sine coefficient, got none");
    for (std::size_t k = 0; k < f.b.size(); ++k) require_finite(f.b[k], "forcing[" + std::to_string(k) + "]");
}
}  // namespace

template <class A, class F>
MapCore<A, F>::MapCore(double eps, A arcs, F forcing, double K_max)
    : eps_(eps), arcs_(std::move(arcs)), forcing_(std::move(forcing)) {
    require_finite(eps, "eps");
    validate_arcs(arcs_);
    validate_forcing(forcing_);
    if (std::isnan(K_max) || !(K_max > 0.0)) bad("K_max must be > 0 (or inf), got " + fmt(K_max));
    band_ = {std::max(arcs_.band_lo(), arcs_kmin(arcs_)), std::min(K_max, arcs_kmax(arcs_))};
}

template <class A, class F>
void MapCore<A, F>::check_point(double phi, double K, const char* who) const {
    require_angle(phi, std::string(who) + ": phi");
    require_finite(K, std::string(who) + ": K");
    if (!(K > band_.lo && K < band_.hi))
        bad(std::string(who) + ": K = " + fmt(K) + " is outside the band (" + fmt(band_.lo) + ", " + fmt(band_.hi) +
            ") where the map is defined");
}

template <class A, class F>
ArcLengths MapCore<A, F>::arc_lengths(double K) const {
    check_point(0.0, K, "arc_lengths");
    return arcs_.at(K);
}

template <class A, class F>
Region MapCore<A, F>::region(double phi, double K) const {
    check_point(phi, K, "region");
    return classify(detail::wrap(phi), K, arcs_.at(K)).region;
}

template <class A, class F>
double MapCore<A, F>::rotation(double phi, double K) const {
    check_point(phi, K, "rotation");
    return classify(detail::wrap(phi), K, arcs_.at(K)).omega;
}

template <class A, class F>
std::pair<Region, double> MapCore<A, F>::classify_point(double phi, double K, const char* who) const {
    check_point(phi, K, who);
    const Classified c = classify(detail::wrap(phi), K, arcs_.at(K));
    return {c.region, c.omega};
}

template <class A, class F>
std::pair<double, double> MapCore<A, F>::step(double phi, double K) const {
    check_point(phi, K, "step");
    const double q = detail::wrap(phi);  // as the kernels, which only ever see wrapped angles
    const double p = detail::rotate(q, classify(q, K, arcs_.at(K)).omega);
    return {p, K + eps_ * forcing_.at(p)};
}

template <class A, class F>
StepJacobian MapCore<A, F>::step_jacobian(double phi, double K) const {
    check_point(phi, K, "jacobian");
    const double q = detail::wrap(phi);
    const ArcLengths a = arcs_.at(K);
    const Classified c = classify(q, K, a);
    StepJacobian out;
    out.phi = detail::rotate(q, c.omega);  // step()'s expressions: the same image bit for bit
    out.K = K + eps_ * forcing_.at(out.phi);
    out.region = c.region;
    const ArcSlopes d = arcs_.slopes(K);
    double w = d.Omega;  // d omega_a / dK of the point's arc (classify.hpp: arc_rotation)
    if (c.region == Region::Upper) w += d.JR;
    if (c.region == Region::Right) w -= d.J1;
    const double g = eps_ * forcing_.slope(out.phi);
    out.J[0] = 1.0;
    out.J[1] = w;
    out.J[2] = g;
    out.J[3] = 1.0 + g * w;
    if (K < 0.0) {
        const detail::ArcStarts s = detail::arc_starts(a);
        if (q == s.s1 || q == s.sR || q == s.s0) out.status = Status::Corner;
    }
    return out;
}

namespace {

// The point of the half-open arc [lo, hi) nearest to q (q itself if it lies there).
double clamp_to_arc(double q, double lo, double hi) {
    if (lo == hi) return lo;  // an arc shorter than an ulp (at the band floor): its only double
    if (detail::in_arc(q, lo, hi)) return q;
    const double last = hi == -kPi ? std::nextafter(kPi, 0.0) : std::nextafter(hi, -kInf);
    return std::fabs(detail::wrap(lo - q)) <= std::fabs(detail::wrap(q - hi)) ? lo : last;
}

// Whether the half-open image arc [t, t_next) of an arc of length len lies in the right order: an
// image arc shorter than the rounding of its ends can come out with t_next an ulp before t, which
// in_arc() would read as almost the whole circle.
bool ordered(double t, double t_next, double len) {
    const double d = t_next - t;
    return (d < 0.0 ? d + kTwoPi : d) - len <= kPi;
}

// The arcs' starts at one height and their images t_a = rotate(s_a, omega_a), computed by the
// forward step's own expression (classify.hpp): the forward image of s_a is t_a to the bit.
struct Starts {
    detail::ArcStarts s;
    double t1, tR, t0;
    explicit Starts(const ArcLengths& a)
        : s(detail::arc_starts(a)),
          t1(detail::rotate(s.s1, detail::arc_rotation(Region::Upper, a))),
          tR(detail::rotate(s.sR, detail::arc_rotation(Region::Right, a))),
          t0(detail::rotate(s.s0, detail::arc_rotation(Region::Above, a))) {}
};

// The start of which p is the forward image at height K (K < 0), if any: s_a with t_a == p and
// s_a owned by its arc (a start whose arc has no double was not rotated by omega_a).
bool start_with_image(double p, double K, const ArcLengths& a, double& start) {
    const Starts st(a);
    const std::pair<double, double> cand[3] = {{st.t1, st.s.s1}, {st.tR, st.s.sR}, {st.t0, st.s.s0}};
    const Region owner[3] = {Region::Upper, Region::Right, Region::Above};
    for (int i = 0; i < 3; ++i)
        if (p == cand[i].first && classify(cand[i].second, K, a).region == owner[i]) {
            start = cand[i].second;
            return true;
        }
    return false;
}

// Which image arc F(J_a) the angle p lies in at a preimage height K: the image arcs come in the
// order J_R', J_1', J_0', each owning its start (the image of the arc's start).
Region image_region(double p, double K, const ArcLengths& a) {
    if (!(K < 0.0)) return Region::Beside;
    const Starts st(a);
    if (ordered(st.t1, st.t0, a.J1) && detail::in_arc(p, st.t1, st.t0)) return Region::Upper;
    if (ordered(st.tR, st.t1, a.JR) && detail::in_arc(p, st.tR, st.t1)) return Region::Right;
    return Region::Above;
}

// The preimage angle of p in arc r: p - omega_r lies in arc r up to rounding, which can carry it
// an ulp across the arc's start; clamping undoes that.
double preimage_angle(double p, Region r, const ArcLengths& a) {
    const double q = detail::wrap(p - detail::arc_rotation(r, a));
    if (r == Region::Beside) return q;
    const detail::ArcStarts s = detail::arc_starts(a);
    if (r == Region::Upper) return clamp_to_arc(q, s.s1, s.sR);
    if (r == Region::Right) return clamp_to_arc(q, s.sR, s.s0);
    return clamp_to_arc(q, s.s0, s.s1);
}

// Doubles in increasing order as integers (+0 and -0 share 0), to bisect over the doubles between two.
std::int64_t order_key(double x) {
    std::int64_t i;
    std::memcpy(&i, &x, sizeof i);
    return i < 0 ? std::numeric_limits<std::int64_t>::min() - i : i;
}
double from_key(std::int64_t k) {
    const std::int64_t i = k < 0 ? std::numeric_limits<std::int64_t>::min() - k : k;
    double x;
    std::memcpy(&x, &i, sizeof x);
    return x;
}

// The double nearest `from` (where pred must be false) on the way to `to` (where it is true) at
// which pred holds, for pred monotone between them.
template <class Pred>
double nearest_true(double from, double to, Pred pred) {
    std::int64_t f = order_key(from), t = order_key(to);
    while (f - t > 1 || t - f > 1) {
        const std::int64_t mid = f + (t - f) / 2;
        (pred(from_key(mid)) ? t : f) = mid;
    }
    return from_key(t);
}

}  // namespace

template <class A, class F>
double MapCore<A, F>::preimage_height(double K1, double kick) const {
    const double K0 = K1 - kick;
    if (K0 > band_.lo && K0 < band_.hi) return K0;
    // The forward step rounds K + kick, so an image of a point just inside the open band can
    // round back onto or past its end (K0 = lo exactly for ~1 in 100 points within 1e-14 of the
    // floor). fl(K + kick) is monotone in K: K1 is an image of a band height iff it lies between
    // the images of the first and last band doubles; the preimage is then clamped to them.
    const double first = std::nextafter(band_.lo, kInf), last = std::nextafter(band_.hi, -kInf);
    if (K0 <= band_.lo && first < band_.hi && first + kick <= K1) return first;
    if (K0 >= band_.hi && last > band_.lo && last + kick >= K1) return last;
    bad("step_inverse (preimage): K = " + fmt(K0) + " is outside the band (" + fmt(band_.lo) + ", " + fmt(band_.hi) +
        ") where the map is defined");
}

template <class A, class F>
bool MapCore<A, F>::merged_start(double p, double K0, double K1, double kick, double& phi0, double& Ks) const {
    // The heights the forward step sends to K1 (fl(k + kick) == K1) form an interval of doubles
    // (rounding is monotone) within ulp(K1) of K0; arcs exist below K = 0 only.
    const double first = std::nextafter(band_.lo, kInf), last = std::nextafter(band_.hi, -kInf);
    const double top = -std::numeric_limits<double>::denorm_min();
    const double reach = 2.0 * (std::nextafter(std::fabs(K1), kInf) - std::fabs(K1));
    const double below = std::max(K0 - reach, first), above = std::min(std::min(K0 + reach, last), top);
    if (!(below < 0.0) || !(below < above)) return false;
    const Region owner[3] = {Region::Upper, Region::Right, Region::Above};
    auto start_of = [](int i, const Starts& st) { return i == 0 ? st.s.s1 : i == 1 ? st.s.sR : st.s.s0; };
    auto image_of = [](int i, const Starts& st) { return i == 0 ? st.t1 : i == 1 ? st.tR : st.t0; };
    auto offset = [&](int i, double k) { return detail::wrap(image_of(i, Starts(arcs_.at(k))) - p); };
    // A start whose image stays clear of p between the two probe heights (by more than the
    // rounding of t_a, a few ulps of 2 pi) is not the one; nearly every p is clear of all three.
    const double slack = 8.0 * (std::nextafter(kTwoPi, kInf) - kTwoPi);
    auto clear = [&](double g1, double g2) { return (g1 > slack && g2 > slack) || (g1 < -slack && g2 < -slack); };
    const Starts at_below(arcs_.at(below)), at_above(arcs_.at(above));
    bool candidate[3];
    bool any = false;
    for (int i = 0; i < 3; ++i)
        any |= candidate[i] = !clear(detail::wrap(image_of(i, at_below) - p), detail::wrap(image_of(i, at_above) - p));
    if (!any) return false;
    auto sent = [&](double k) { return k + kick == K1; };
    const double kmin = sent(below) ? below : nearest_true(below, K0, sent);
    const double kmax = std::min(sent(above) ? above : nearest_true(above, K0, sent), top);
    if (!(kmin < kmax)) return false;
    // Search the interval for a height k at which a candidate start's image t_a(k) is p exactly,
    // the heights nearest K0 first. t_a moves with k, but its own rounding (a few ulps of
    // |Omega| + 3 pi) is not monotone in k and can exceed that motion over the whole interval, so
    // an interval of up to 4096 doubles is searched entirely; a longer one (|K| << |K1|, where
    // the sqrt(-K) of |J_1| makes t_a move fast) is bisected on the side of p that t_a lies on,
    // and the 64 doubles either side of the crossing are searched.
    const std::int64_t lo_k = order_key(kmin), hi_k = order_key(kmax);
    auto hit = [&](int i, std::int64_t kk) {
        const double k = from_key(kk);
        const ArcLengths a = arcs_.at(k);
        const Starts st(a);
        if (!(image_of(i, st) == p && classify(start_of(i, st), k, a).region == owner[i])) return false;
        phi0 = start_of(i, st);
        Ks = k;
        return true;
    };
    auto search = [&](std::int64_t c, std::int64_t half_width, auto&& arcs_to_try) {
        for (std::int64_t n = 0; n <= 2 * half_width; ++n) {
            const std::int64_t kk = n % 2 ? c - (n + 1) / 2 : c + n / 2;  // c, c - 1, c + 1, c - 2, ...
            if (kk < lo_k || kk > hi_k) continue;
            for (int i = 0; i < 3; ++i)
                if (arcs_to_try(i) && hit(i, kk)) return true;
        }
        return false;
    };
    constexpr std::int64_t kWhole = 4096, kScan = 64;
    if (hi_k - lo_k <= kWhole)
        return search(std::min(std::max(order_key(K0), lo_k), hi_k), hi_k - lo_k, [&](int i) { return candidate[i]; });
    for (int i = 0; i < 3; ++i) {
        if (!candidate[i]) continue;
        const double glo = offset(i, kmin), ghi = offset(i, kmax);
        double centre = std::fabs(glo) <= std::fabs(ghi) ? kmin : kmax;
        if ((glo < 0.0) != (ghi < 0.0)) {
            const bool rising = glo < 0.0;
            centre = nearest_true(kmin, kmax, [&](double k) { return (offset(i, k) >= 0.0) == rising; });
        }
        if (search(order_key(centre), kScan, [&](int j) { return j == i; })) return true;
    }
    return false;
}

template <class A, class F>
std::pair<double, double> MapCore<A, F>::step_inverse(double phi, double K1) const {
    require_angle(phi, "step_inverse: phi");
    require_finite(K1, "step_inverse: K");
    const double p = detail::wrap(phi);
    const double kick = eps_ * forcing_.at(p);
    const double K0 = preimage_height(K1, kick);
    const ArcLengths a0 = arcs_.at(K0);
    // The image of an arc start is given back to that start, to the bit (the arc owns its start;
    // p - omega_a alone can land an ulp beside it). The forward step also rounds K + kick to K1, so
    // every height of an interval of doubles around K0 (more than one when ulp(K1) > ulp(K0)) is
    // sent to K1 - the float map merges them - and the image of the start s_a(K) of a merged
    // height K can lie on the other side of t_a(K0), in the image of the arc before: it has two
    // float preimages. It goes to the start too, at its own height.
    double start;
    if (K0 < 0.0 && start_with_image(p, K0, a0, start)) return {start, K0};
    double phi_s, K_s;
    if (K0 + kick == K1 && merged_start(p, K0, K1, kick, phi_s, K_s)) return {phi_s, K_s};
    return {preimage_angle(p, image_region(p, K0, a0), a0), K0};
}

template <class A, class F>
std::vector<double> MapCore<A, F>::arc_starts(double K) const {
    check_point(0.0, K, "arc_starts");
    if (!(K < 0.0)) bad("arc_starts: the arcs exist only for K < 0, got K = " + fmt(K));
    const detail::ArcStarts s = detail::arc_starts(arcs_.at(K));
    return {s.s1, s.sR, s.s0};
}

template class MapCore<AnalyticArcs, SineForcing>;
template class MapCore<TabulatedArcs, FourierForcing>;

TruncatedMap make_truncated_map(double eps, double Omega0, double theta_w, double tau0, double tau1, double lam,
                                double K_max) {
    return TruncatedMap(eps, AnalyticArcs{Omega0, theta_w, tau0, tau1, lam}, SineForcing{}, K_max);
}

}  // namespace hovering
