// Batch iteration: SIMD kernel vs scalar kernel, thread-count invariance, statuses and recording.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "hovering/truncated/map.hpp"
#include "testing.hpp"

using namespace hovering;
namespace {
const double kPi = 3.14159265358979323846;

struct Run {
    std::vector<double> pf, kf, op, ok, rot;
    std::vector<std::int8_t> reg, st;
    std::vector<std::int64_t> done, ex;
};

Run run(const TruncatedMap& m, const std::vector<double>& p0, const std::vector<double>& k0, std::int64_t ns,
        Kernel kern, int threads, unsigned mask = 0, bool stop = false, const std::atomic<bool>* cancel = nullptr) {
    const std::size_t n = p0.size();
    Run r;
    r.pf.resize(n);
    r.kf.resize(n);
    r.rot.resize(n);
    r.st.resize(n);
    r.done.resize(n);
    r.ex.resize(n);
    r.op.resize(n * (ns + 1));
    r.ok.resize(n * (ns + 1));
    r.reg.resize(n * ns);
    IterateOptions o;
    o.n_steps = ns;
    o.kernel = kern;
    o.n_threads = threads;
    o.exit_mask = mask;
    o.stop_on_exit = stop;
    o.cancel = cancel;
    IterateOutput out;
    out.phi_final = r.pf.data();
    out.K_final = r.kf.data();
    out.orbit_phi = r.op.data();
    out.orbit_K = r.ok.data();
    out.regions = r.reg.data();
    out.rotation = r.rot.data();
    out.status = r.st.data();
    out.steps_done = r.done.data();
    out.exit_step = r.ex.data();
    m.iterate(p0.data(), k0.data(), std::int64_t(n), o, out);
    return r;
}
}  // namespace

TEST_CASE("batch iteration: kernels, threads, statuses, recording, exit watch, cancellation", "[truncated][iterate]") {
    const double OmegaG = kPi * (std::sqrt(5.0) - 1.0);
    TruncatedMap m = make_truncated_map(0.3, OmegaG, 3 * kPi / 4, 1.0, 0.5, 0.5);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> uphi(-kPi, kPi), uK(-0.3, 0.3);
    const std::size_t n = 1003;  // not a multiple of the chunk or lane width on purpose
    std::vector<double> p0(n), k0(n);
    for (std::size_t i = 0; i < n; ++i) {
        p0[i] = uphi(rng);
        k0[i] = uK(rng);
    }

    // Same kernel, 1 vs 2 threads: bit-identical (orbits are independent).
    Run a = run(m, p0, k0, 200, Kernel::Simd, 1), b = run(m, p0, k0, 200, Kernel::Simd, 2);
    CHECKF(a.pf == b.pf && a.kf == b.kf && a.reg == b.reg && a.st == b.st, "thread count changed SIMD results");

    // SIMD vs scalar over 5 steps: SLEEF sin and libm sin differ by ~1 ulp, so states agree to
    // ~1e-15 per step; 1e-12 allows the ~5 steps of growth. (Longer orbits diverge: the map is chaotic.)
    Run s = run(m, p0, k0, 5, Kernel::Scalar, 1), v = run(m, p0, k0, 5, Kernel::Simd, 1);
    double worst = 0;
    int reg_diff = 0;
    for (std::size_t i = 0; i < n; ++i) {
        worst = std::max({worst, std::fabs(wrap_angle(s.pf[i] - v.pf[i])), std::fabs(s.kf[i] - v.kf[i])});
        for (int j = 0; j < 5; ++j) reg_diff += s.reg[i * 5 + j] != v.reg[i * 5 + j];
    }
    CHECKF(worst < 1e-12, "SIMD vs scalar after 5 steps: %.3g", worst);
    CHECKF(reg_diff == 0, "SIMD and scalar regions differ at %d steps", reg_diff);

    // Recorded orbit = repeated single steps; rotation = mean omega of the recorded steps.
    Run r = run(m, p0, k0, 50, Kernel::Scalar, 2);
    double worst_orbit = 0, worst_rot = 0;
    for (std::size_t i = 0; i < 50; ++i) {
        double p = p0[i], k = k0[i], sum = 0;
        std::int64_t nd = r.done[i];
        for (std::int64_t j = 0; j < nd; ++j) {
            sum += m.rotation(p, k);
            CHECKF(r.reg[i * 50 + j] == static_cast<std::int8_t>(m.region(p, k)), "recorded region");
            auto nx = m.step(p, k);
            p = nx.first;
            k = nx.second;
            worst_orbit =
                std::max(worst_orbit, std::fabs(r.op[i * 51 + j + 1] - p) + std::fabs(r.ok[i * 51 + j + 1] - k));
        }
        if (nd > 0) worst_rot = std::max(worst_rot, std::fabs(r.rot[i] - sum / double(nd)));
    }
    CHECKF(worst_orbit == 0.0, "scalar orbit differs from repeated step(): %.3g", worst_orbit);
    CHECKF(worst_rot < 1e-12, "rotation mean off by %.3g", worst_rot);

    // Escape: an orbit started just above the band floor with a downward kick leaves the band;
    // it stops with Escaped, keeps the escaped image, and the tail of its orbit is NaN.
    const double lo = m.band().lo;
    std::vector<double> pe, ke;
    for (int i = 0; i < 64; ++i) {
        pe.push_back(-kPi + i * 0.098);
        ke.push_back(lo + 1e-3);
    }
    pe.push_back(0.0);
    ke.push_back(lo - 1.0);  // starts outside: Escaped with 0 steps
    for (Kernel kern : {Kernel::Simd, Kernel::Scalar}) {
        Run e = run(m, pe, ke, 1000, kern, 2);
        int esc = 0;
        for (std::size_t i = 0; i < pe.size(); ++i) {
            if (e.st[i] != static_cast<std::int8_t>(Status::Escaped)) continue;
            ++esc;
            std::int64_t d = e.done[i];
            CHECKF(!(e.kf[i] > lo), "escaped orbit %zu has K=%g inside the band", i, e.kf[i]);
            if (d < 1000) CHECKF(std::isnan(e.op[i * 1001 + d + 1]), "tail must be NaN");
            if (d < 1000) CHECKF(e.reg[i * 1000 + d] == -1, "region tail must be None");
            CHECKF(e.op[i * 1001 + d] == e.pf[i], "last recorded point is the final state");
        }
        CHECKF(esc >= 2, "expected escapes near the band floor, got %d", esc);
        CHECKF(e.st.back() == static_cast<std::int8_t>(Status::Escaped) && e.done.back() == 0, "outside start");
    }

    // Exit watch: stay in {Beside, Above}; the first exit step matches a direct scan, in both kernels.
    unsigned mask = (1u << 0) | (1u << 1);
    for (Kernel kern : {Kernel::Simd, Kernel::Scalar}) {
        Run w = run(m, p0, k0, 300, kern, 2, mask, false);
        Run st = run(m, p0, k0, 300, kern, 2, mask, true);
        int checked = 0;
        for (std::size_t i = 0; i < 200; ++i) {
            std::int64_t first = -1;
            for (std::int64_t j = 0; j < w.done[i]; ++j)
                if (w.reg[i * 300 + j] >= 2) {
                    first = j;
                    break;
                }
            CHECKF(w.ex[i] == first, "orbit %zu: exit_step %lld vs scan %lld", i, (long long)w.ex[i], (long long)first);
            if (first >= 0) {
                ++checked;
                CHECKF(st.st[i] == static_cast<std::int8_t>(Status::Exited) && st.done[i] == first, "stop_on_exit");
            }
        }
        CHECKF(checked > 20, "too few exits to test: %d", checked);
    }

    // Cancellation before the start: every orbit Interrupted at step 0, nothing lost or garbage.
    std::atomic<bool> cancel{true};
    Run c = run(m, p0, k0, 100, Kernel::Simd, 2, 0, false, &cancel);
    bool all_int = true;
    for (std::size_t i = 0; i < n; ++i)
        all_int &= c.st[i] == static_cast<std::int8_t>(Status::Interrupted) && c.done[i] == 0 && c.pf[i] == p0[i];
    CHECKF(all_int, "cancelled run must report Interrupted with the initial state");

    // Bad options.
    IterateOptions o;
    o.n_steps = -1;
    IterateOutput out;
    CHECK_INVALID(m.iterate(p0.data(), k0.data(), 1, o, out), "n_steps must be >= 0");
    o.n_steps = 1;
    o.exit_mask = 1u << kRegionCount;  // region codes are 0 .. kRegionCount - 1
    CHECK_INVALID(m.iterate(p0.data(), k0.data(), 1, o, out), "exit_mask");
    std::vector<double> pn = {0.0, NAN};
    o.exit_mask = 0;
    CHECK_INVALID(m.iterate(pn.data(), k0.data(), 2, o, out), "phi0[1] must be finite");
    o.n_threads = 1 << 29;  // used to overflow 8 * threads (SIGFPE); now a clear error
    CHECK_INVALID(m.iterate(p0.data(), k0.data(), 1, o, out), "n_threads must be in [0, 4096]");
    o.n_threads = 0;
    std::vector<double> big = {1e18};
    CHECK_INVALID(m.iterate(big.data(), k0.data(), 1, o, out), "<= 1e6");
    CHECK_INVALID(m.step(-1e18, 0.1), "<= 1e6");
}

TEST_CASE("batch iteration: the progress counter ends at n * n_steps, early exits credited", "[truncated][iterate]") {
    const double OmegaG = kPi * (std::sqrt(5.0) - 1.0);
    TruncatedMap m = make_truncated_map(0.3, OmegaG, 3 * kPi / 4, 1.0, 0.5, 0.5, 1.0);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> U(-kPi, kPi), V(-0.4, 0.4);
    std::vector<double> p0(3000), k0(3000);
    for (std::size_t i = 0; i < p0.size(); ++i) {
        p0[i] = U(rng);
        k0[i] = V(rng);
    }
    k0[5] = 2.0;  // outside the band (K_max = 1): escaped at once, its steps credited
    const unsigned no_impact = (1u << int(Region::Beside)) | (1u << int(Region::Above));
    for (Kernel kern : {Kernel::Simd, Kernel::Scalar}) {
        for (int threads : {1, 2}) {
            std::atomic<std::int64_t> progress{0};
            std::vector<std::int8_t> st(p0.size());
            IterateOptions o;
            o.n_steps = 700;
            o.kernel = kern;
            o.n_threads = threads;
            o.exit_mask = no_impact;
            o.stop_on_exit = true;
            o.progress = &progress;
            IterateOutput out;
            out.status = st.data();
            m.iterate(p0.data(), k0.data(), std::int64_t(p0.size()), o, out);
            CHECKF(progress.load() == std::int64_t(p0.size()) * 700, "kernel %d, %d threads: %lld", int(kern), threads,
                   (long long)progress.load());
            CHECK(std::count(st.begin(), st.end(), static_cast<std::int8_t>(Status::Exited)) > 0);
            CHECK(st[5] == static_cast<std::int8_t>(Status::Escaped));
        }
    }
}

TEST_CASE("every SIMD level this CPU runs, forced: its width, the scalar kernel's regions, states to 1e-12",
          "[truncated][iterate][simd]") {
    TruncatedMap m = make_truncated_map(0.3, kPi * (std::sqrt(5.0) - 1.0), 3 * kPi / 4, 1.0, 0.5, 0.5);
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> uphi(-kPi, kPi), uK(-0.3, 0.3);
    const std::size_t n = 1003;
    std::vector<double> p0(n), k0(n);
    for (std::size_t i = 0; i < n; ++i) {
        p0[i] = uphi(rng);
        k0[i] = uK(rng);
    }
    const std::string chosen = simd_level();
    const std::vector<std::string> levels = simd_levels();
    // x86-64 always runs the SSE2 build (a non-x86 or native build has one level of its own).
    CHECKF(!levels.empty(), "no SIMD level");
    set_simd_level("auto");
    CHECKF(simd_level() == levels.back(), "auto selected %s, the widest is %s", simd_level().c_str(),
           levels.back().c_str());
    const Run s = run(m, p0, k0, 5, Kernel::Scalar, 1);
    for (const std::string& level : levels) {
        set_simd_level(level);
        const int want = level == "avx512" ? 8 : level == "avx2" ? 4 : level == "sse2" ? 2 : simd_width();
        CHECKF(simd_level() == level && simd_width() == want, "forced %s: level %s, width %d (want %d)", level.c_str(),
               simd_level().c_str(), simd_width(), want);
        // As in the kernels test above: SLEEF's sin is within 1 ulp of libm's, so 5 steps agree to
        // 1e-12; regions agree exactly; threads change nothing.
        const Run v = run(m, p0, k0, 5, Kernel::Simd, 1), w = run(m, p0, k0, 5, Kernel::Simd, 2);
        CHECKF(v.pf == w.pf && v.kf == w.kf && v.reg == w.reg, "%s: thread count changed results", level.c_str());
        double worst = 0;
        int reg_diff = 0;
        for (std::size_t i = 0; i < n; ++i) {
            worst = std::max({worst, std::fabs(wrap_angle(s.pf[i] - v.pf[i])), std::fabs(s.kf[i] - v.kf[i])});
            for (int j = 0; j < 5; ++j) reg_diff += s.reg[i * 5 + j] != v.reg[i * 5 + j];
        }
        CHECKF(worst < 1e-12 && reg_diff == 0, "%s vs scalar after 5 steps: %.3g, %d regions differ", level.c_str(),
               worst, reg_diff);
    }
    // A level this build has not (or this CPU does not run): an error naming it and the choices;
    // the selection stays.
    set_simd_level(levels.front());
    CHECK_INVALID(set_simd_level("avx1024"), "got 'avx1024'");
    CHECK_INVALID(set_simd_level("avx1024"), "must be one of auto, " + levels.front());
    CHECKF(simd_level() == levels.front(), "a failed set_simd_level changed the level to %s", simd_level().c_str());
    set_simd_level(chosen);
}
