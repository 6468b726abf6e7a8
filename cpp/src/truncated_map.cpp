// Implementation of the truncated family. Compiled with -fno-trapping-math -fno-math-errno (see
// CMakeLists.txt): without them GCC will not if-convert Eigen's select() chains or inline sqrt,
// and the chunk kernel below falls back to scalar code. Neither flag changes IEEE results.

#include "hovering/truncated_map.hpp"

#include "detail.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_spline.h>
#include <sleef.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#if defined(__AVX2__) || defined(__SSE2__)
#include <immintrin.h>
#endif

namespace hovering {

namespace {

using detail::bad;
using detail::fmt;
using detail::gsl_quiet;
using detail::kInf;
using detail::kPi;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kInvTwoPi = 1.0 / kTwoPi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void require_finite(double v, const std::string& name) {
    if (!std::isfinite(v)) bad(name + " must be finite, got " + fmt(v));
}

// Beyond this, 2 pi floor(phi / 2 pi) is off by more than one turn in double precision, so an
// angle cannot be wrapped meaningfully; 1e6 keeps the wrapping error below 1e-9.
constexpr double kMaxAngle = 1e6;
constexpr int kMaxThreads = 4096;

void require_angle(double v, const std::string& name) {
    require_finite(v, name);
    if (!(std::fabs(v) <= kMaxAngle))
        bad(name + " must be an angle with |" + name + "| <= 1e6 (larger angles cannot be wrapped to [-pi, pi) "
            "accurately in double precision), got " + fmt(v));
}

namespace ei = Eigen::internal;
// The SIMD register type Eigen picked for this build (AVX-512, AVX, SSE2 or plain double).
using Packet = ei::packet_traits<double>::type;
constexpr int kW = ei::packet_traits<double>::size;  // (unpacket_traits<Packet> trips -Wignored-attributes)

// sin on one packet with SLEEF's vector sin for this instruction set: max error 1.0 ulp, or 3.5 ulp
// (about 20% faster per step) when Fast is set.
template <bool Fast>
inline Packet psin(const Packet& x) {
#if defined(EIGEN_VECTORIZE_AVX512)
    return Fast ? Sleef_sind8_u35avx512f(x) : Sleef_sind8_u10avx512f(x);
#elif defined(EIGEN_VECTORIZE_AVX) && defined(__AVX2__) && defined(__FMA__)
    return Fast ? Sleef_sind4_u35avx2(x) : Sleef_sind4_u10avx2(x);
#elif defined(EIGEN_VECTORIZE_AVX)
    return Fast ? Sleef_sind4_u35avx(x) : Sleef_sind4_u10avx(x);
#elif defined(EIGEN_VECTORIZE_SSE4_1)
    return Fast ? Sleef_sind2_u35sse4(x) : Sleef_sind2_u10sse4(x);
#elif defined(EIGEN_VECTORIZE_SSE2)
    return Fast ? Sleef_sind2_u35sse2(x) : Sleef_sind2_u10sse2(x);
#else
    return Fast ? Sleef_sin_u35(x) : Sleef_sin_u10(x);
#endif
}

struct Classified {
    Region region;
    double omega;
};

// The one place where a point is assigned to an arc; the SIMD kernel repeats exactly this arithmetic.
Classified classify(double phi, double K, const ArcLengths& a) {
    if (!(K < 0.0)) return {Region::Beside, a.Omega};
    double d = phi - (kPi - 0.5 * (a.Omega + a.JR + a.J1));  // offset from the left end of J_1
    d -= kTwoPi * std::floor(d * kInvTwoPi);
    if (d < a.J1) return {Region::Upper, a.Omega + a.JR};
    if (d < a.J1 + a.JR) return {Region::Right, a.Omega - a.J1};
    return {Region::Above, a.Omega};
}

// Arc lengths of a packet of heights: packet arithmetic for the analytic model, in the same
// operation order as AnalyticArcs::at so that both kernels round alike ...
inline void arcs_packet(const AnalyticArcs& a, const Packet& k, Packet& Om, Packet& JR, Packet& J1) {
    const Packet zero = ei::pset1<Packet>(0.0);
    Om = ei::padd(ei::pset1<Packet>(a.Omega0), ei::pmul(ei::pset1<Packet>(a.tau0), k));
    J1 = ei::pmul(ei::pset1<Packet>(2.0 * a.lam), ei::psqrt(ei::pmax(ei::pnegate(k), zero)));
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
inline Packet force_packet(const SineForcing&, const Packet& p) { return psin<Fast>(p); }

template <bool Fast>
inline Packet force_packet(const FourierForcing& f, const Packet& p) {
    Packet acc = ei::pset1<Packet>(0.0);
    for (std::size_t k = 0; k < f.b.size(); ++k)
        if (f.b[k] != 0.0)
            acc = ei::padd(acc, ei::pmul(ei::pset1<Packet>(f.b[k]), psin<Fast>(ei::pmul(ei::pset1<Packet>(double(k + 1)), p))));
    return acc;
}

}  // namespace

double wrap_angle(double x) {
    double y = x - kTwoPi * std::floor((x + kPi) * kInvTwoPi);
    if (y >= kPi) y -= kTwoPi;
    if (y < -kPi) y += kTwoPi;
    return y;
}

bool simd_is_avx2() {
#if defined(__AVX2__)
    return true;
#else
    return false;
#endif
}

// ---------------------------------------------------------------------------------------------
// Analytic arcs

void AnalyticArcs::validate() const {
    require_finite(Omega0, "Omega0");
    require_finite(theta_w, "theta_w");
    require_finite(tau0, "tau0");
    require_finite(tau1, "tau1");
    require_finite(lam, "lam");
    if (!(theta_w > 0.0 && theta_w < kPi))
        bad("theta_w must lie in (0, pi) = (0, 3.141592653589793), got " + fmt(theta_w));
    if (!(lam > 0.0)) bad("lam must be > 0, got " + fmt(lam));
}

ArcLengths AnalyticArcs::at(double K) const {
    if (!(K < 0.0)) return {Omega0 + tau0 * K, 0.0, 0.0};
    return {Omega0 + tau0 * K, 2.0 * (kPi - theta_w) + tau1 * K, 2.0 * lam * std::sqrt(-K)};
}

double AnalyticArcs::band_lo() const {
    // With K = -s^2 the three lengths are |J_1| = 2 lam s, |J_R| = 2(pi - theta_w) - tau1 s^2 and
    // |J_0| = 2 pi - |J_1| - |J_R|; all lie in (0, 2 pi) iff |J_R| > 0 and |J_0| > 0.
    double lo = -kInf;
    // |J_0| > 0  <=>  g(s) = tau1 s^2 - 2 lam s + 2 theta_w > 0; g(0) > 0, first root (if any) is
    // 2 theta_w / (lam + sqrt(lam^2 - 2 tau1 theta_w)), written this way to avoid cancellation.
    const double disc = lam * lam - 2.0 * tau1 * theta_w;
    if (disc >= 0.0) {
        const double s1 = 2.0 * theta_w / (lam + std::sqrt(disc));
        lo = std::max(lo, -s1 * s1);
    }
    if (tau1 > 0.0) lo = std::max(lo, -2.0 * (kPi - theta_w) / tau1);  // |J_R| > 0
    return lo;
}

// ---------------------------------------------------------------------------------------------
// Splines and tabulated arcs

Spline::Spline(std::vector<double> x, std::vector<double> y, const char* name)
    : x_(std::move(x)), y_(std::move(y)), name_(name), spline_(nullptr) {
    gsl_quiet();
    const std::string n(name);
    if (x_.size() != y_.size())
        bad(n + ": grid and values differ in length (" + std::to_string(x_.size()) + " vs " +
            std::to_string(y_.size()) + ")");
    if (x_.size() < 3) bad(n + ": needs at least 3 grid points, got " + std::to_string(x_.size()));
    for (std::size_t i = 0; i < x_.size(); ++i) {
        require_finite(x_[i], n + " grid[" + std::to_string(i) + "]");
        require_finite(y_[i], n + " value[" + std::to_string(i) + "]");
        if (i > 0 && !(x_[i] > x_[i - 1]))
            bad(n + ": grid must be strictly increasing, but grid[" + std::to_string(i) + "] = " +
                fmt(x_[i]) + " <= grid[" + std::to_string(i - 1) + "] = " + fmt(x_[i - 1]));
    }
    gsl_spline* s = gsl_spline_alloc(gsl_interp_cspline, x_.size());
    if (!s) throw std::bad_alloc();
    if (gsl_spline_init(s, x_.data(), y_.data(), x_.size()) != GSL_SUCCESS) {
        gsl_spline_free(s);
        bad(n + ": GSL could not build the cubic spline");
    }
    spline_ = s;
}

Spline::Spline(const Spline& o) : Spline(o.x_, o.y_, o.name_) {}

Spline::~Spline() {
    if (spline_) gsl_spline_free(static_cast<gsl_spline*>(spline_));
}

double Spline::operator()(double x) const {
    // Clamp rounding-level excursions; callers keep x inside the grid (the band is inside it).
    x = std::min(std::max(x, x_.front()), x_.back());
    return gsl_spline_eval(static_cast<const gsl_spline*>(spline_), x, nullptr);
}

namespace {

std::vector<double> nonpositive_part(const std::vector<double>& K, const std::vector<double>& v,
                                     bool in_s) {
    // Points with K <= 0; in s = sqrt(-K) they must be reversed to stay increasing.
    std::vector<double> out;
    for (std::size_t i = 0; i < K.size(); ++i)
        if (K[i] <= 0.0) out.push_back(in_s ? std::sqrt(-K[i]) : v[i]);
    if (in_s) std::reverse(out.begin(), out.end());
    return out;
}

std::vector<double> nonpositive_values_reversed(const std::vector<double>& K,
                                                const std::vector<double>& v) {
    std::vector<double> out;
    for (std::size_t i = 0; i < K.size(); ++i)
        if (K[i] <= 0.0) out.push_back(v[i]);
    std::reverse(out.begin(), out.end());
    return out;
}

void check_table(const std::vector<double>& K, const std::vector<double>& Omega,
                 const std::vector<double>& JR, const std::vector<double>& J1) {
    if (Omega.size() != K.size() || JR.size() != K.size() || J1.size() != K.size())
        bad("K, Omega, JR and J1 must have the same length, got " + std::to_string(K.size()) + ", " +
            std::to_string(Omega.size()) + ", " + std::to_string(JR.size()) + ", " +
            std::to_string(J1.size()));
    bool has_zero = false;
    std::size_t n_nonpos = 0;
    // Checked here with the caller's indices: the splines see reordered copies.
    for (std::size_t i = 0; i < K.size(); ++i) {
        require_finite(K[i], "K[" + std::to_string(i) + "]");
        require_finite(Omega[i], "Omega[" + std::to_string(i) + "]");
        require_finite(JR[i], "JR[" + std::to_string(i) + "]");
        require_finite(J1[i], "J1[" + std::to_string(i) + "]");
    }
    for (std::size_t i = 0; i < K.size(); ++i) {
        if (K[i] == 0.0) {
            has_zero = true;
            // |J_1| = O(sqrt(-K)) closes at the tangency circle; a table that says otherwise is not
            // a near-tangency model.
            if (std::abs(J1[i]) > 1e-9)
                bad("J1 must vanish at K = 0 (|J_1| closes on the tangency circle), got " + fmt(J1[i]));
        }
        if (K[i] <= 0.0) ++n_nonpos;
    }
    if (!has_zero) bad("the K grid must contain K = 0 exactly (the tangency circle)");
    if (n_nonpos < 3)
        bad("the K grid needs at least 3 points with K <= 0, got " + std::to_string(n_nonpos));
    if (!(K.back() > 0.0)) bad("the K grid must extend above K = 0, got max K = " + fmt(K.back()));
}

}  // namespace

TabulatedArcs::TabulatedArcs(const std::vector<double>& K, const std::vector<double>& Omega_v,
                             const std::vector<double>& JR_v, const std::vector<double>& J1_v)
    : Omega((check_table(K, Omega_v, JR_v, J1_v), K), Omega_v, "Omega"),
      JR(nonpositive_part(K, K, false), nonpositive_part(K, JR_v, false), "JR"),
      J1s(nonpositive_part(K, K, true), nonpositive_values_reversed(K, J1_v), "J1") {}

ArcLengths TabulatedArcs::at(double K) const {
    if (!(K < 0.0)) return {Omega(K), 0.0, 0.0};
    return {Omega(K), JR(K), J1s(std::sqrt(-K))};
}

double TabulatedArcs::band_lo() const {
    auto ok = [this](double s) {
        const ArcLengths a = at(-s * s);
        return a.J1 > 0.0 && a.JR > 0.0 && a.J1 + a.JR < kTwoPi;
    };
    const double smax = J1s.xmax();
    const std::size_t n = 64 * J1s.x().size();
    double good = 0.0;
    for (std::size_t i = 1; i <= n; ++i) {
        const double s = smax * double(i) / double(n);
        if (ok(s)) {
            good = s;
            continue;
        }
        if (good == 0.0)
            bad("the tabulated arcs give no valid band below K = 0: at K = " + fmt(-s * s) +
                " the arc lengths (|J_R|, |J_1|) = (" + fmt(at(-s * s).JR) + ", " +
                fmt(at(-s * s).J1) + ") are not all in (0, 2 pi)");
        double badv = s;  // bisect the first failure between the last good and first bad sample
        for (int it = 0; it < 200 && badv - good > 1e-15 * badv; ++it) {
            const double mid = 0.5 * (good + badv);
            (ok(mid) ? good : badv) = mid;
        }
        return -good * good;
    }
    return -smax * smax;
}

// ---------------------------------------------------------------------------------------------
// Forcings

double SineForcing::at(double phi) const { return std::sin(phi); }

double FourierForcing::at(double phi) const {
    double f = 0.0;
    for (std::size_t k = 0; k < b.size(); ++k)
        if (b[k] != 0.0) f += b[k] * std::sin(double(k + 1) * phi);
    return f;
}

// ---------------------------------------------------------------------------------------------
// MapCore

namespace {
double arcs_kmax(const AnalyticArcs&) { return kInf; }
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
    band_ = {arcs_.band_lo(), std::min(K_max, arcs_kmax(arcs_))};
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

// ------------------------------------------------------------------ batch iteration

namespace {

// Writes an orbit's outputs once it stops, and the NaN / None tail of its recorded arrays.
struct Finisher {
    const IterateOptions& opt;
    const IterateOutput& out;
    void start(std::int64_t i, double phi, double K) const {
        if (out.orbit_phi) out.orbit_phi[i * (opt.n_steps + 1)] = phi;
        if (out.orbit_K) out.orbit_K[i * (opt.n_steps + 1)] = K;
        if (out.exit_step) out.exit_step[i] = -1;
    }
    void operator()(std::int64_t i, double phi, double K, double rotsum, std::int64_t steps,
                    Status st) const {
        const std::int64_t ns = opt.n_steps;
        if (out.phi_final) out.phi_final[i] = phi;
        if (out.K_final) out.K_final[i] = K;
        if (out.rotation) out.rotation[i] = steps > 0 ? rotsum / double(steps) : kNaN;
        if (out.status) out.status[i] = static_cast<std::int8_t>(st);
        if (out.steps_done) out.steps_done[i] = steps;
        if (out.orbit_phi)
            std::fill(out.orbit_phi + i * (ns + 1) + steps + 1, out.orbit_phi + (i + 1) * (ns + 1), kNaN);
        if (out.orbit_K)
            std::fill(out.orbit_K + i * (ns + 1) + steps + 1, out.orbit_K + (i + 1) * (ns + 1), kNaN);
        if (out.regions)
            std::fill(out.regions + i * ns + steps, out.regions + (i + 1) * ns,
                      static_cast<std::int8_t>(Region::None));
    }
};

bool cancelled(const IterateOptions& opt) {
    return opt.cancel && opt.cancel->load(std::memory_order_relaxed);
}

}  // namespace

// Hands out orbit indices to one worker from the shared counter, a block at a time.
struct OrbitSource {
    std::atomic<std::int64_t>& next;
    std::int64_t n, block, cur = 0, end = 0;
    bool pop(std::int64_t& i) {
        if (cur == end) {
            cur = next.fetch_add(block);
            if (cur >= n) {
                cur = end = n;
                return false;
            }
            end = std::min(n, cur + block);
        }
        i = cur++;
        return true;
    }
};

namespace {
// Packets in flight per worker: several independent dependency chains hide the latency of one
// step (sqrt, floor, sin) while the whole state stays in registers / L1.
constexpr int kP = 8;
constexpr int kLanes = kP * kW;
}  // namespace

template <class A, class F>
template <bool Fast>
void MapCore<A, F>::run_simd(const double* phi0, const double* K0, OrbitSource& src,
                             const IterateOptions& opt, const IterateOutput& out) const {
    // Lane kernel on Eigen packets: kLanes orbits are stepped together; an orbit that stops frees
    // its lane, which is refilled from the source at once, so the vectors stay full even when
    // orbits stop at very different times (early exit). Per-lane bookkeeping happens on a rare
    // path that unpacks the packets into lane arrays and packs them back.
    const Finisher finish{opt, out};
    const std::int64_t ns = opt.n_steps;
    const double lo = band_.lo, hi = band_.hi;
    const bool watch = opt.exit_mask != 0;
    const bool need_reg = watch || out.regions;  // region codes are only built when read
    const Packet zero = ei::pset1<Packet>(0.0), one = ei::pset1<Packet>(1.0), two = ei::pset1<Packet>(2.0),
                 three = ei::pset1<Packet>(3.0), pi = ei::pset1<Packet>(kPi), mpi = ei::pset1<Packet>(-kPi),
                 twopi = ei::pset1<Packet>(kTwoPi), inv2pi = ei::pset1<Packet>(kInvTwoPi),
                 half = ei::pset1<Packet>(0.5), eps = ei::pset1<Packet>(eps_), plo = ei::pset1<Packet>(lo),
                 phi_ = ei::pset1<Packet>(hi), all = ei::pcmp_eq(zero, zero);
    Packet allow[4];
    for (int r = 0; r < 4; ++r) allow[r] = (opt.exit_mask >> r) & 1u ? all : zero;

    Packet phi[kP], K[kP], rot[kP], live[kP], fresh[kP], reg[kP], omega[kP];
    alignas(64) double lphi[kLanes], lK[kLanes], lrot[kLanes], llive[kLanes], lfresh[kLanes], lreg[kLanes];
    std::int64_t idx[kLanes], start[kLanes];
    std::int64_t it = 0;  // iterations of this worker; lane j has taken it - start[j] steps

    auto unpack = [&] {
        for (int q = 0; q < kP; ++q) {
            ei::pstore(lphi + q * kW, phi[q]);
            ei::pstore(lK + q * kW, K[q]);
            ei::pstore(lrot + q * kW, rot[q]);
            ei::pstore(llive + q * kW, live[q]);
            ei::pstore(lfresh + q * kW, fresh[q]);
        }
    };
    auto pack = [&] {
        for (int q = 0; q < kP; ++q) {
            phi[q] = ei::pload<Packet>(lphi + q * kW);
            K[q] = ei::pload<Packet>(lK + q * kW);
            rot[q] = ei::pload<Packet>(lrot + q * kW);
            live[q] = ei::pload<Packet>(llive + q * kW);
            fresh[q] = ei::pload<Packet>(lfresh + q * kW);
        }
    };
    const double on = [] { double x; const std::uint64_t b = ~std::uint64_t(0); std::memcpy(&x, &b, 8); return x; }();
    auto is_live = [&](int j) { return std::memcmp(&llive[j], &on, 8) == 0; };
    // Put the next orbit that starts inside the band into lane j (orbits starting outside finish
    // at once); with no work left the lane computes a harmless point that is ignored everywhere.
    auto fill = [&](int j) {
        for (std::int64_t i; src.pop(i);) {
            finish.start(i, phi0[i], K0[i]);
            if (!(K0[i] > lo && K0[i] < hi)) {
                finish(i, phi0[i], K0[i], 0.0, 0, Status::Escaped);
                continue;
            }
            if (ns == 0) {
                finish(i, phi0[i], K0[i], 0.0, 0, Status::Ok);
                continue;
            }
            lphi[j] = phi0[i];
            lK[j] = K0[i];
            lrot[j] = 0.0;
            llive[j] = on;
            lfresh[j] = on;  // not yet reported as leaving the watched regions
            idx[j] = i;
            start[j] = it;
            return true;
        }
        lphi[j] = 0.0;
        lK[j] = 0.0;
        lrot[j] = 0.0;
        llive[j] = 0.0;
        lfresh[j] = 0.0;
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
    std::int64_t countdown = next_completion();

    while (nlive > 0) {
        if ((it & 63) == 0 && cancelled(opt)) {
            unpack();
            for (int j = 0; j < kLanes; ++j)
                if (is_live(j)) finish(idx[j], lphi[j], lK[j], lrot[j], it - start[j], Status::Interrupted);
            for (std::int64_t i; src.pop(i);) {  // not started: keep their initial state
                finish.start(i, phi0[i], K0[i]);
                const bool inside = K0[i] > lo && K0[i] < hi;
                finish(i, phi0[i], K0[i], 0.0, 0, inside ? Status::Interrupted : Status::Escaped);
            }
            return;
        }
        // Classify every lane: region code and rotation omega_a (same arithmetic as classify()).
        Packet leaving = zero;
        for (int q = 0; q < kP; ++q) {
            Packet Om, JR, J1;
            arcs_packet(arcs_, K[q], Om, JR, J1);
            Packet d = ei::psub(phi[q], ei::psub(pi, ei::pmul(half, ei::padd(ei::padd(Om, JR), J1))));
            d = ei::psub(d, ei::pmul(twopi, ei::pfloor(ei::pmul(d, inv2pi))));
            const Packet neg = ei::pcmp_lt(K[q], zero);
            const Packet up = ei::pand(neg, ei::pcmp_lt(d, J1));
            const Packet rt = ei::pandnot(ei::pand(neg, ei::pcmp_lt(d, ei::padd(J1, JR))), up);
            omega[q] = ei::psub(ei::padd(Om, ei::pand(up, JR)), ei::pand(rt, J1));
            if (!need_reg) continue;
            reg[q] = ei::pselect(neg, ei::pselect(up, two, ei::pselect(rt, three, one)), zero);
            if (watch) {
                const Packet ok = ei::pselect(ei::pcmp_eq(reg[q], zero), allow[0],
                                  ei::pselect(ei::pcmp_eq(reg[q], one), allow[1],
                                  ei::pselect(ei::pcmp_eq(reg[q], two), allow[2], allow[3])));
                leaving = ei::por(leaving, ei::pandnot(ei::pand(live[q], fresh[q]), ok));
            }
        }
        if (watch && ei::predux_any(leaving)) {
            unpack();
            for (int q = 0; q < kP; ++q) ei::pstore(lreg + q * kW, reg[q]);
            bool refilled = false;
            for (int j = 0; j < kLanes; ++j) {
                if (!is_live(j) || std::memcmp(&lfresh[j], &on, 8) != 0) continue;
                if ((opt.exit_mask >> int(lreg[j])) & 1u) continue;
                if (out.exit_step) out.exit_step[idx[j]] = it - start[j];
                lfresh[j] = 0.0;
                if (opt.stop_on_exit) {
                    finish(idx[j], lphi[j], lK[j], lrot[j], it - start[j], Status::Exited);
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
        if (out.regions) {
            for (int q = 0; q < kP; ++q) ei::pstore(lreg + q * kW, reg[q]);
            ei::pstore(llive, live[0]);  // lane liveness is only read here and on the rare path
            for (int q = 1; q < kP; ++q) ei::pstore(llive + q * kW, live[q]);
            for (int j = 0; j < kLanes; ++j)
                if (is_live(j)) out.regions[idx[j] * ns + (it - start[j])] = static_cast<std::int8_t>(lreg[j]);
        }
        // Step: rotate, wrap to [-pi, pi), kick.
        Packet outside = zero;
        for (int q = 0; q < kP; ++q) {
            rot[q] = ei::padd(rot[q], omega[q]);
            Packet p = ei::padd(phi[q], omega[q]);
            p = ei::psub(p, ei::pmul(twopi, ei::pfloor(ei::pmul(ei::padd(p, pi), inv2pi))));
            p = ei::pselect(ei::pcmp_le(pi, p), ei::psub(p, twopi), p);
            p = ei::pselect(ei::pcmp_lt(p, mpi), ei::padd(p, twopi), p);
            phi[q] = p;
            K[q] = ei::padd(K[q], ei::pmul(eps, force_packet<Fast>(forcing_, p)));
            const Packet inside = ei::pand(ei::pcmp_lt(plo, K[q]), ei::pcmp_lt(K[q], phi_));
            outside = ei::por(outside, ei::pandnot(live[q], inside));
        }
        ++it;
        --countdown;
        if (out.orbit_phi || out.orbit_K) {
            unpack();
            for (int j = 0; j < kLanes; ++j) {
                if (!is_live(j)) continue;
                const std::int64_t at = idx[j] * (ns + 1) + (it - start[j]);
                if (out.orbit_phi) out.orbit_phi[at] = lphi[j];
                if (out.orbit_K) out.orbit_K[at] = lK[j];
            }
        }
        if (countdown == 0 || ei::predux_any(outside)) {
            unpack();
            for (int j = 0; j < kLanes; ++j) {
                if (!is_live(j)) continue;
                if (!(lK[j] > lo && lK[j] < hi))
                    finish(idx[j], lphi[j], lK[j], lrot[j], it - start[j], Status::Escaped);
                else if (it - start[j] == ns)
                    finish(idx[j], lphi[j], lK[j], lrot[j], ns, Status::Ok);
                else
                    continue;
                nlive -= !fill(j);
            }
            pack();
            countdown = next_completion();
        }
    }
}

template <class A, class F>
void MapCore<A, F>::run_scalar(const double* phi0, const double* K0, OrbitSource& src,
                               const IterateOptions& opt, const IterateOutput& out) const {
    const Finisher finish{opt, out};
    const std::int64_t ns = opt.n_steps;
    for (std::int64_t i; src.pop(i);) {
        double phi = phi0[i], K = K0[i], rot = 0.0;
        finish.start(i, phi, K);
        bool reported = false;
        std::int64_t n = 0;
        Status st = Status::Ok;
        if (!(K > band_.lo && K < band_.hi)) {
            finish(i, phi, K, 0.0, 0, Status::Escaped);
            continue;
        }
        for (; n < ns; ++n) {
            if ((n & 63) == 0 && cancelled(opt)) {
                st = Status::Interrupted;
                break;
            }
            const Classified c = classify(phi, K, arcs_.at(K));
            if (opt.exit_mask && !reported && !((opt.exit_mask >> int(c.region)) & 1u)) {
                if (out.exit_step) out.exit_step[i] = n;
                reported = true;
                if (opt.stop_on_exit) {
                    st = Status::Exited;
                    break;
                }
            }
            if (out.regions) out.regions[i * ns + n] = static_cast<std::int8_t>(c.region);
            rot += c.omega;
            phi = wrap_angle(phi + c.omega);
            K += eps_ * forcing_.at(phi);
            if (out.orbit_phi) out.orbit_phi[i * (ns + 1) + n + 1] = phi;
            if (out.orbit_K) out.orbit_K[i * (ns + 1) + n + 1] = K;
            if (!(K > band_.lo && K < band_.hi)) {
                st = Status::Escaped;
                ++n;
                break;
            }
        }
        finish(i, phi, K, rot, n, st);
    }
}

template <class A, class F>
void MapCore<A, F>::iterate(const double* phi0, const double* K0, std::int64_t n,
                            const IterateOptions& opt, const IterateOutput& out) const {
    if (n < 0) bad("number of orbits must be >= 0, got " + std::to_string(n));
    if (opt.n_steps < 0) bad("n_steps must be >= 0, got " + std::to_string(opt.n_steps));
    if (opt.exit_mask > 15u)
        bad("exit_mask must be a set of regions 0..3 (a bit mask <= 15), got " +
            std::to_string(opt.exit_mask));
    if (opt.stop_on_exit && opt.exit_mask == 0u)
        bad("stop_on_exit needs a non-empty set of regions to stay in");
    if (opt.n_threads < 0 || opt.n_threads > kMaxThreads)
        bad("n_threads must be in [0, " + std::to_string(kMaxThreads) + "] (0 = all cores), got " +
            std::to_string(opt.n_threads));
    for (std::int64_t i = 0; i < n; ++i) {
        require_angle(phi0[i], "phi0[" + std::to_string(i) + "]");
        require_finite(K0[i], "K0[" + std::to_string(i) + "]");
    }
    if (n == 0) return;

    std::int64_t threads = opt.n_threads > 0 ? opt.n_threads : std::int64_t(std::thread::hardware_concurrency());
    // A worker needs at least a lane-block's worth of orbits to fill its vectors.
    threads = std::clamp<std::int64_t>(threads, 1, (n + kLanes - 1) / kLanes);
    // Small blocks keep threads balanced when orbits stop at different times.
    const std::int64_t block = std::clamp<std::int64_t>((n + 8 * threads - 1) / (8 * threads), 1, 256);

    std::atomic<std::int64_t> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto worker = [&] {
        try {
            OrbitSource src{next, n, block};
            if (opt.kernel == Kernel::Simd && opt.fast_sin)
                run_simd<true>(phi0, K0, src, opt, out);
            else if (opt.kernel == Kernel::Simd)
                run_simd<false>(phi0, K0, src, opt, out);
            else
                run_scalar(phi0, K0, src, opt, out);
        } catch (...) {
            std::lock_guard<std::mutex> lock(error_mutex);
            if (!error) error = std::current_exception();
            next.store(n);
        }
    };
    if (threads == 1) {
        worker();
    } else {
        std::vector<std::thread> pool;
        pool.reserve(std::size_t(threads));
        try {
            for (std::int64_t t = 0; t < threads; ++t) pool.emplace_back(worker);
        } catch (...) {
            // Could not start a thread: stop the ones running (they drain no more work), then report.
            next.store(n);
            for (auto& t : pool) t.join();
            throw;
        }
        for (auto& t : pool) t.join();
    }
    if (error) std::rethrow_exception(error);
}

template class MapCore<AnalyticArcs, SineForcing>;
template class MapCore<TabulatedArcs, FourierForcing>;

TruncatedMap make_truncated_map(double eps, double Omega0, double theta_w, double tau0, double tau1,
                                double lam, double K_max) {
    return TruncatedMap(eps, AnalyticArcs{Omega0, theta_w, tau0, tau1, lam}, SineForcing{}, K_max);
}

}  // namespace hovering
