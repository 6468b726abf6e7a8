// MapCore: construction and validation, single forward and backward steps, arcs on a circle.

#include "hovering/truncated/map.hpp"

#include <cmath>
#include <string>

#include "hovering/detail/common.hpp"
#include "hovering/truncated/classify.hpp"

namespace hovering {

using detail::bad;
using detail::classify;
using detail::Classified;
using detail::fmt;
using detail::kInf;
using detail::kPi;
using detail::require_angle;
using detail::require_finite;

// ---------------------------------------------------------------------------------------------
// MapCore

namespace {
// The band ends where the rotation |Omega0 + tau0 K| reaches 1e6 rad: beyond, phi + Omega cannot
// be wrapped meaningfully (K0 = 1e21 iterated to phi = 1.3e5, "OK"; tau0 = 4e20 the same below 0).
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
double arcs_kmin(const TabulatedArcs&) { return -kInf; }
double arcs_kmax(const TabulatedArcs& a) { return a.kmax(); }
void validate_arcs(const AnalyticArcs& a) { a.validate(); }
void validate_arcs(const TabulatedArcs&) {}
void validate_forcing(const SineForcing&) {}
void validate_forcing(const FourierForcing& f) {
    if (f.b.empty()) bad("forcing needs at least one sine coefficient, got none");
    for (std::size_t k = 0; k < f.b.size(); ++k)
        require_finite(f.b[k], "forcing[" + std::to_string(k) + "]");
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
        bad(std::string(who) + ": K = " + fmt(K) + " is outside the band (" + fmt(band_.lo) + ", " +
            fmt(band_.hi) + ") where the map is defined");
}

template <class A, class F>
ArcLengths MapCore<A, F>::arc_lengths(double K) const {
    check_point(0.0, K, "arc_lengths");
    return arcs_.at(K);
}

template <class A, class F>
Region MapCore<A, F>::region(double phi, double K) const {
    check_point(phi, K, "region");
    return classify(phi, K, arcs_.at(K)).region;
}

template <class A, class F>
double MapCore<A, F>::rotation(double phi, double K) const {
    check_point(phi, K, "rotation");
    return classify(phi, K, arcs_.at(K)).omega;
}

template <class A, class F>
std::pair<Region, double> MapCore<A, F>::classify_point(double phi, double K, const char* who) const {
    check_point(phi, K, who);
    const Classified c = classify(phi, K, arcs_.at(K));
    return {c.region, c.omega};
}

template <class A, class F>
std::pair<double, double> MapCore<A, F>::step(double phi, double K) const {
    check_point(phi, K, "step");
    const double p = wrap_angle(phi + classify(phi, K, arcs_.at(K)).omega);
    return {p, K + eps_ * forcing_.at(p)};
}

template <class A, class F>
std::pair<double, double> MapCore<A, F>::step_inverse(double phi, double K) const {
    require_angle(phi, "step_inverse: phi");
    require_finite(K, "step_inverse: K");
    const double K0 = K - eps_ * forcing_.at(phi);
    check_point(phi, K0, "step_inverse (preimage)");
    // The exchange maps J_a(K) onto the reflected arc -J_a(K) (lem:truncreturnmap), so the region
    // of the preimage is the region of -phi.
    return {wrap_angle(phi - classify(-phi, K0, arcs_.at(K0)).omega), K0};
}

template <class A, class F>
std::vector<double> MapCore<A, F>::arc_starts(double K) const {
    check_point(0.0, K, "arc_starts");
    if (!(K < 0.0)) bad("arc_starts: the arcs exist only for K < 0, got K = " + fmt(K));
    const ArcLengths a = arcs_.at(K);
    const double p01 = kPi - 0.5 * (a.Omega + a.JR + a.J1);
    return {wrap_angle(p01), wrap_angle(p01 + a.J1), wrap_angle(p01 + a.J1 + a.JR)};
}

template class MapCore<AnalyticArcs, SineForcing>;
template class MapCore<TabulatedArcs, FourierForcing>;

TruncatedMap make_truncated_map(double eps, double Omega0, double theta_w, double tau0, double tau1,
                                double lam, double K_max) {
    return TruncatedMap(eps, AnalyticArcs{Omega0, theta_w, tau0, tau1, lam}, SineForcing{}, K_max);
}

}  // namespace hovering
