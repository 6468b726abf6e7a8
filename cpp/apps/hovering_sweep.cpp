// hovering_sweep: sweep eps for the truncated map F_eps without Python.
//
// For each eps, a grid of initial conditions over [-pi, pi) x [K_lo, K_hi) is iterated with early
// exit from the no-impact set {J_0u, J_0}; one CSV row per eps gives how many orbits never impacted
// and the area they cover, next to the leading-order hovering area eq:hovsetsize. Rows are appended
// and flushed as each eps finishes, and a rerun skips the points already in the file, so an
// interrupted sweep loses nothing it had computed.
//
// A row is "already computed" only if every input that changes its numbers matches (eps, the map
// parameters, the K box, the grid and the step count; not the thread count), so one file can hold
// several sweeps and a rerun with other settings never passes off an old row as its own. A file
// with another header is refused rather than mixed, and a last row torn by a kill is dropped and
// recomputed instead of being counted as done or glued to the next row.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "hovering/truncated/map.hpp"

namespace {

const double kPi = 3.14159265358979323846;

/// Bytes held per orbit of the grid: phi0 and K0 (double) and the status code.
constexpr std::uint64_t kBytesPerOrbit = 2 * sizeof(double) + sizeof(std::int8_t);

// A grid count resolves the area to box / n_orbits; past 2^31 orbits (36 GB of grid, 2e13 map
// steps at the default --steps) that is below 1e-9 of the box, far under the O(eps^2) error
// of the theory column it is compared with, so a larger grid is almost surely a typo.
constexpr std::uint64_t kMaxOrbitsHard = std::uint64_t(1) << 31;

// Results first, in the positions of earlier versions; then every other input that keys a row.
const char* const kHeader =
    "eps,n_orbits,never_impact,impact,escaped,area_never_impact,box_area,theory_eq_hovsetsize,steps,"
    "Omega0,theta_w,tau0,tau1,lam,K_lo,K_hi,n_phi,n_K";
constexpr std::size_t kColumns = 18;

struct Args {
    std::vector<double> eps;
    double Omega0 = kPi * (std::sqrt(5.0) - 1.0), theta_w = 3 * kPi / 4, tau0 = 1, tau1 = 0.5, lam = 0.5;
    double K_lo = -0.5, K_hi = 0.0;
    long n_phi = 200, n_K = 50, steps = 10000;
    int threads = 0;
    std::string out;
};

/// Every input that changes a row's numbers; equal keys mean the same computation.
struct Key {
    double eps, Omega0, theta_w, tau0, tau1, lam, K_lo, K_hi;
    long n_phi, n_K, steps;
    bool operator==(const Key& o) const {
        return eps == o.eps && Omega0 == o.Omega0 && theta_w == o.theta_w && tau0 == o.tau0 && tau1 == o.tau1 &&
               lam == o.lam && K_lo == o.K_lo && K_hi == o.K_hi && n_phi == o.n_phi && n_K == o.n_K &&
               steps == o.steps;
    }
};

/// The key of the row that these arguments compute for this eps.
Key key_of(const Args& a, double eps) {
    return {eps, a.Omega0, a.theta_w, a.tau0, a.tau1, a.lam, a.K_lo, a.K_hi, a.n_phi, a.n_K, a.steps};
}

// What main was allocating, for the out-of-memory message (a fixed buffer: no allocation needed
// to report a failed one).
char g_stage[512] = "starting";

[[noreturn]] void usage_error(const std::string& msg) {
    throw std::invalid_argument(msg + "\nrun 'hovering_sweep --help' for the options");
}

/// Shortest text that reads back as exactly this double: a readable and exact resume key.
std::string num(double x) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

double parse_double(const std::string& key, const std::string& v) {
    std::size_t pos = 0;
    double x = 0;
    try {
        x = std::stod(v, &pos);
    } catch (...) {
        pos = 0;
    }
    if (v.empty() || pos != v.size() || !std::isfinite(x))
        usage_error(key + " must be a finite number, got '" + v + "'");
    return x;
}

long parse_long(const std::string& key, const std::string& v, long lo, long hi) {
    std::size_t pos = 0;
    long x = 0;
    try {
        x = std::stol(v, &pos);
    } catch (...) {
        pos = 0;
    }
    if (v.empty() || pos != v.size() || x < lo || x > hi)
        usage_error(key + " must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + v + "'");
    return x;
}

/// Split at every comma, keeping empty parts so that "0.1," or "0.1,,0.2" is reported, not ignored.
std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> parts(1);
    for (char c : s) {
        if (c == ',')
            parts.emplace_back();
        else
            parts.back() += c;
    }
    return parts;
}

/// Half of the physical memory in bytes, or 0 if the system does not say.
std::uint64_t half_physical_memory() {
#if defined(_SC_PHYS_PAGES) && defined(_SC_PAGE_SIZE)
    const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    if (pages > 0 && page > 0) return std::uint64_t(pages) * std::uint64_t(page) / 2;
#endif
    return 0;
}

/// Bytes as a short human-readable figure.
std::string human_bytes(double b) {
    char buf[32];
    if (b >= 1e9)
        std::snprintf(buf, sizeof buf, "%.1f GB", b / 1e9);
    else if (b >= 1e6)
        std::snprintf(buf, sizeof buf, "%.1f MB", b / 1e6);
    else
        std::snprintf(buf, sizeof buf, "%.0f bytes", b);
    return buf;
}

const char* kHelp =
    "usage: hovering_sweep --eps E1,E2,... --out FILE.csv [options]\n"
    "  --Omega0 X --theta_w X (0 < X < pi) --tau0 X --tau1 X --lam X (> 0)   map parameters (paper's defaults)\n"
    "  --K-range LO,HI        box of initial K (LO < HI <= 0 within the band; default -0.5,0)\n"
    "  --grid NPHI,NK         initial conditions per eps (default 200,50; NPHI * NK limited by memory)\n"
    "  --steps N              iterates that count as 'never impacts' (default 10000)\n"
    "  --threads T            worker threads, 0 = all cores (default 0)\n"
    "Appends one CSV row per eps to FILE (repeated eps are computed once). A row already in FILE with\n"
    "the same eps and the same other options (all but --threads) is skipped (resume); rows with other\n"
    "options stay in FILE untouched. A FILE with another header is refused; a torn last row (from a\n"
    "killed run) is dropped and recomputed.\n";

Args parse(int argc, char** argv) {
    Args a;
    for (int i = 1; i < argc; ++i) {
        const std::string key = argv[i];
        if (key == "--help" || key == "-h") {
            std::cout << kHelp;
            std::exit(0);
        }
        if (i + 1 >= argc) usage_error("option " + key + " needs a value");
        const std::string v = argv[++i];
        if (key == "--eps") {
            for (const auto& p : split(v)) a.eps.push_back(parse_double("--eps", p));
        } else if (key == "--Omega0") {
            a.Omega0 = parse_double(key, v);
        } else if (key == "--theta_w") {
            a.theta_w = parse_double(key, v);
        } else if (key == "--tau0") {
            a.tau0 = parse_double(key, v);
        } else if (key == "--tau1") {
            a.tau1 = parse_double(key, v);
        } else if (key == "--lam") {
            a.lam = parse_double(key, v);
        } else if (key == "--K-range") {
            const auto p = split(v);
            if (p.size() != 2) usage_error("--K-range needs LO,HI, got '" + v + "'");
            a.K_lo = parse_double(key, p[0]);
            a.K_hi = parse_double(key, p[1]);
        } else if (key == "--grid") {
            const auto p = split(v);
            if (p.size() != 2) usage_error("--grid needs NPHI,NK, got '" + v + "'");
            a.n_phi = parse_long(key, p[0], 1, 100000);
            a.n_K = parse_long(key, p[1], 1, 100000);
        } else if (key == "--steps") {
            a.steps = parse_long(key, v, 1, 1000000000L);
        } else if (key == "--threads") {
            a.threads = int(parse_long(key, v, 0, 4096));
        } else if (key == "--out") {
            a.out = v;
        } else {
            usage_error("unknown option '" + key + "'; allowed: --eps --Omega0 --theta_w --tau0 --tau1 --lam "
                        "--K-range --grid --steps --threads --out --help");
        }
    }
    if (a.eps.empty()) usage_error("--eps is required (a comma-separated list)");
    if (a.out.empty()) usage_error("--out is required (the CSV file)");
    {
        namespace fs = std::filesystem;
        std::error_code ec;
        const fs::path out(a.out);
        if (fs::is_directory(out, ec)) usage_error("--out must name a file, got the directory '" + a.out + "'");
        const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
        if (!fs::is_directory(dir, ec))
            usage_error("--out '" + a.out + "': the directory '" + dir.string() + "' does not exist");
    }
    // Checked here (the map checks them too) so that the message names the option.
    if (!(a.theta_w > 0.0 && a.theta_w < kPi))
        usage_error("--theta_w must lie in (0, pi) = (0, 3.141592653589793), got " + num(a.theta_w));
    if (!(a.lam > 0.0)) usage_error("--lam must be > 0, got " + num(a.lam));
    if (!(a.K_lo < a.K_hi && a.K_hi <= 0.0))
        usage_error("--K-range must satisfy LO < HI <= 0, got " + num(a.K_lo) + "," + num(a.K_hi));

    // Build every map now, so that any parameter the core rejects stops the run before the file is
    // touched, not after the header and the first rows.
    double band_lo = -std::numeric_limits<double>::infinity();
    for (double eps : a.eps) {
        try {
            band_lo = hovering::make_truncated_map(eps, a.Omega0, a.theta_w, a.tau0, a.tau1, a.lam).band().lo;
        } catch (const std::invalid_argument& e) {
            usage_error(std::string("map parameters rejected: ") + e.what());
        }
    }
    // Initial points below the band are not orbits of the map at all; the cell centres lie above K_lo.
    if (!(a.K_lo >= band_lo))
        usage_error("--K-range LO must be >= " + num(band_lo) +
                    " (the lower edge of the band where the map is defined for these --theta_w --tau1 --lam), got " +
                    num(a.K_lo));

    const std::uint64_t n = std::uint64_t(a.n_phi) * std::uint64_t(a.n_K);
    const std::uint64_t half_mem = half_physical_memory();
    std::uint64_t max_orbits = kMaxOrbitsHard;
    std::string why = "2^31";
    if (half_mem > 0 && half_mem / kBytesPerOrbit < max_orbits) {
        max_orbits = half_mem / kBytesPerOrbit;
        why = "half of this machine's " + human_bytes(2.0 * double(half_mem)) + " of physical memory at " +
              std::to_string(kBytesPerOrbit) + " bytes per orbit";
    }
    if (n > max_orbits)
        usage_error("--grid " + std::to_string(a.n_phi) + "," + std::to_string(a.n_K) + " asks for n_phi * n_K = " +
                    std::to_string(n) + " orbits (" + human_bytes(double(n) * kBytesPerOrbit) +
                    "); allowed: n_phi * n_K <= " + std::to_string(max_orbits) + " (" + why + ")");

    // Each eps once, in the order first given: a repeat would only recompute the same row.
    std::vector<double> unique;
    for (double e : a.eps) {
        bool seen = false;
        for (double u : unique) seen = seen || u == e;
        if (seen)
            std::cerr << "eps = " << num(e) << " is listed more than once; computed once\n";
        else
            unique.push_back(e);
    }
    a.eps = unique;
    return a;
}

/// Why this CSV line is not a row of kHeader ("" if it is one); fills key when it is.
std::string check_row(const std::string& line, Key& key) {
    const auto f = split(line);
    if (f.size() != kColumns)
        return "it has " + std::to_string(f.size()) + " fields, expected " + std::to_string(kColumns);
    double d[kColumns] = {};
    long l[kColumns] = {};
    // Counts must read back as integers; the reals may be inf or nan (theory at sin(Omega0 / 2) = 0).
    static const bool is_count[kColumns] = {false, true, true, true, true, false, false, false, true,
                                            false, false, false, false, false, false, false, true, true};
    for (std::size_t c = 0; c < kColumns; ++c) {
        const char* b = f[c].data();
        const char* e = b + f[c].size();
        const auto r = is_count[c] ? std::from_chars(b, e, l[c]) : std::from_chars(b, e, d[c]);
        if (f[c].empty() || r.ec != std::errc() || r.ptr != e)
            return "field " + std::to_string(c + 1) + " ('" + f[c] + "') is not a number";
    }
    key = {d[0], d[9], d[10], d[11], d[12], d[13], d[14], d[15], l[16], l[17], l[8]};
    return "";
}

/// What the existing output file holds, as far as resuming is concerned.
struct Existing {
    bool write_header = true;    ///< the file is new, empty, or only held a torn header
    bool torn = false;           ///< its last line is incomplete or invalid and must go
    std::uintmax_t keep = 0;     ///< bytes to keep when torn (the end of the last valid line)
    std::string torn_note;       ///< what was wrong with the dropped line
    std::vector<Key> keys;       ///< keys of its complete rows
};

/// Columns of a header line, for saying how a foreign header differs from kHeader.
std::string header_difference(const std::string& theirs) {
    const auto want = split(kHeader), have = split(theirs);
    std::string missing, extra;
    for (const auto& w : want) {
        bool found = false;
        for (const auto& h : have) found = found || h == w;
        if (!found) missing += (missing.empty() ? "" : ",") + w;
    }
    for (const auto& h : have) {
        bool found = false;
        for (const auto& w : want) found = found || h == w;
        if (!found) extra += (extra.empty() ? "" : ",") + h;
    }
    if (missing.empty() && extra.empty()) return "the same columns in another order";
    std::string s;
    if (!missing.empty()) s += "missing columns " + missing;
    if (!extra.empty()) s += std::string(s.empty() ? "" : "; ") + "columns this version does not write " + extra;
    return s;
}

/// Read the output file: refuse a foreign header or a damaged row inside it, find a torn tail.
Existing scan(const std::string& path) {
    Existing ex;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return ex;
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read " + path + " (to resume from it)");
    std::string line, bad_note;
    std::uintmax_t offset = 0;
    long lineno = 0, bad_line = 0;
    while (std::getline(in, line)) {
        // getline sets eof only when the line ran to the end of the file without a newline.
        const bool complete = !in.eof();
        ++lineno;
        if (bad_line)
            throw std::runtime_error(path + " line " + std::to_string(bad_line) + " is not a valid row (" + bad_note +
                                     ") and rows follow it, so it is not a row torn by an interrupted run: the "
                                     "file was edited or damaged. Fix or remove that line, or use another --out.");
        if (lineno == 1) {
            if (!complete && std::string(kHeader).compare(0, line.size(), line) == 0) {
                ex.torn = true;  // killed while writing the header: start the file again
                ex.keep = 0;
                ex.torn_note = "an incomplete header";
            } else if (line != kHeader) {
                throw std::runtime_error(path + " does not have the header this version of hovering_sweep writes (" +
                                         header_difference(line) +
                                         "): it is an older format or another program's file, and rows of this "
                                         "version would not match its columns. Use another --out file, or move " +
                                         path + " away.\n  expected: " + kHeader + "\n  found:    " + line);
            } else {
                ex.write_header = false;
            }
        } else {
            Key k{};
            const std::string why = complete ? check_row(line, k) : "no newline at its end";
            if (why.empty()) {
                ex.keys.push_back(k);
            } else {
                bad_line = lineno;
                bad_note = why;
                ex.keep = offset;
                ex.torn_note = "line " + std::to_string(lineno) + " '" + line.substr(0, 60) +
                               (line.size() > 60 ? "..." : "") + "': " + why;
            }
        }
        offset += line.size() + (complete ? 1 : 0);
    }
    if (in.bad()) throw std::runtime_error("error reading " + path);
    if (bad_line) ex.torn = true;
    return ex;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const Args a = parse(argc, argv);
        std::snprintf(g_stage, sizeof g_stage, "reading %s to resume (is it a CSV written by hovering_sweep?)",
                      a.out.c_str());
        const Existing ex = scan(a.out);
        std::vector<double> todo;
        for (double eps : a.eps) {
            bool done = false;
            for (const auto& k : ex.keys) done = done || k == key_of(a, eps);
            if (done)
                std::cerr << "eps = " << num(eps) << ": already in " << a.out << " with these options, skipped\n";
            else
                todo.push_back(eps);
        }

        // The grid is allocated before the file is touched, so running out of memory leaves it as it was.
        const long long n = (long long)a.n_phi * a.n_K;
        std::vector<double> phi0, K0;
        std::vector<std::int8_t> status;
        if (!todo.empty()) {
            std::snprintf(g_stage, sizeof g_stage,
                          "allocating the grid of --grid %ld,%ld = %lld orbits (%s); reduce --grid", a.n_phi, a.n_K, n,
                          human_bytes(double(n) * kBytesPerOrbit).c_str());
            phi0.resize(std::size_t(n));
            K0.resize(std::size_t(n));
            status.resize(std::size_t(n));
            for (long long i = 0; i < a.n_phi; ++i)
                for (long long j = 0; j < a.n_K; ++j) {
                    phi0[std::size_t(i * a.n_K + j)] = -kPi + (double(i) + 0.5) * 2 * kPi / double(a.n_phi);
                    K0[std::size_t(i * a.n_K + j)] = a.K_lo + (double(j) + 0.5) * (a.K_hi - a.K_lo) / double(a.n_K);
                }
        }

        std::snprintf(g_stage, sizeof g_stage, "writing %s", a.out.c_str());
        if (ex.torn) {
            std::filesystem::resize_file(a.out, ex.keep);
            std::cerr << "hovering_sweep: " << a.out << ": dropped a torn row (" << ex.torn_note
                      << "), left by an interrupted run; it is recomputed if requested\n";
        }
        if (todo.empty()) return 0;
        std::ofstream csv(a.out, std::ios::app | std::ios::binary);
        if (!csv) throw std::runtime_error("cannot open " + a.out + " for appending");
        if (ex.write_header) csv << kHeader << '\n' << std::flush;
        if (!csv) throw std::runtime_error("cannot write the header to " + a.out);

        const double box = 2 * kPi * (a.K_hi - a.K_lo);
        for (double eps : todo) {
            std::snprintf(g_stage, sizeof g_stage,
                          "iterating eps = %s (worker threads and their buffers); reduce --threads or --grid",
                          num(eps).c_str());
            const auto m = hovering::make_truncated_map(eps, a.Omega0, a.theta_w, a.tau0, a.tau1, a.lam);
            hovering::IterateOptions opt;
            opt.n_steps = a.steps;
            opt.exit_mask = (1u << int(hovering::Region::Beside)) | (1u << int(hovering::Region::Above));
            opt.stop_on_exit = true;
            opt.n_threads = a.threads;
            hovering::IterateOutput out;
            out.status = status.data();
            m.iterate(phi0.data(), K0.data(), n, opt, out);
            long long ok = 0, exited = 0, escaped = 0;
            for (auto s : status) {
                ok += s == std::int8_t(hovering::Status::Ok);
                exited += s == std::int8_t(hovering::Status::Exited);
                escaped += s == std::int8_t(hovering::Status::Escaped);
            }
            const double theory = eps > 0 ? eps * (std::sin(a.theta_w) - a.theta_w * std::cos(a.theta_w)) /
                                                std::sin(0.5 * a.Omega0)
                                          : 0.0;
            char results[256];
            std::snprintf(results, sizeof results, "%lld,%lld,%lld,%lld,%.10g,%.10g,%.10g,%ld", n, ok, exited, escaped,
                          box * double(ok) / double(n), box, theory, a.steps);
            const std::string row = num(eps) + "," + results + "," + num(a.Omega0) + "," + num(a.theta_w) + "," +
                                    num(a.tau0) + "," + num(a.tau1) + "," + num(a.lam) + "," + num(a.K_lo) + "," +
                                    num(a.K_hi) + "," + std::to_string(a.n_phi) + "," + std::to_string(a.n_K) + "\n";
            csv << row << std::flush;  // on disk, in one write, before the next eps starts
            if (!csv) throw std::runtime_error("writing a row to " + a.out + " failed (disk full?)");
            std::cerr << row;
        }
        return 0;
    } catch (const std::bad_alloc&) {
        std::cerr << "hovering_sweep: out of memory while " << g_stage << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "hovering_sweep: " << e.what() << "\n";
        return 2;
    }
}
