// hovering_sweep: sweep eps for the truncated map F_eps without Python.
//
// For each eps, a grid of initial conditions over [-pi, pi) x [K_lo, K_hi) is iterated with early
// exit from the no-impact set {J_0u, J_0}; one CSV row per eps gives how many orbits never impacted
// and the area they cover, next to the leading-order hovering area eq:hovsetsize. Rows are appended
// and flushed as each eps finishes, and a rerun skips the eps already in the file, so an interrupted
// sweep loses nothing it had computed.

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hovering/truncated/map.hpp"

namespace {

const double kPi = 3.14159265358979323846;

struct Args {
    std::vector<double> eps;
    double Omega0 = kPi * (std::sqrt(5.0) - 1.0), theta_w = 3 * kPi / 4, tau0 = 1, tau1 = 0.5, lam = 0.5;
    double K_lo = -0.5, K_hi = 0.0;
    long n_phi = 200, n_K = 50, steps = 10000;
    int threads = 0;
    std::string out;
};

[[noreturn]] void usage_error(const std::string& msg) {
    throw std::invalid_argument(msg + "\nrun 'hovering_sweep --help' for the options");
}

double parse_double(const std::string& key, const std::string& v) {
    std::size_t pos = 0;
    double x = 0;
    try {
        x = std::stod(v, &pos);
    } catch (...) {
        pos = 0;
    }
    if (pos != v.size() || !std::isfinite(x)) usage_error(key + " must be a finite number, got '" + v + "'");
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
    if (pos != v.size() || x < lo || x > hi)
        usage_error(key + " must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + v + "'");
    return x;
}

const char* kHelp =
    "usage: hovering_sweep --eps E1,E2,... --out FILE.csv [options]\n"
    "  --Omega0 X --theta_w X (0 < X < pi) --tau0 X --tau1 X --lam X (> 0)   map parameters (paper's defaults)\n"
    "  --K-range LO,HI        box of initial K (LO < HI <= 0 within the band; default -0.5,0)\n"
    "  --grid NPHI,NK         initial conditions per eps (default 200,50)\n"
    "  --steps N              iterates that count as 'never impacts' (default 10000)\n"
    "  --threads T            worker threads, 0 = all cores (default 0)\n"
    "Appends one CSV row per eps to FILE; eps already in FILE are skipped (resume).\n";

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
        auto list = [&](const std::string& s) {
            std::vector<std::string> parts;
            std::stringstream ss(s);
            for (std::string p; std::getline(ss, p, ',');) parts.push_back(p);
            return parts;
        };
        if (key == "--eps") {
            for (const auto& p : list(v)) a.eps.push_back(parse_double("--eps", p));
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
            const auto p = list(v);
            if (p.size() != 2) usage_error("--K-range needs LO,HI, got '" + v + "'");
            a.K_lo = parse_double(key, p[0]);
            a.K_hi = parse_double(key, p[1]);
        } else if (key == "--grid") {
            const auto p = list(v);
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
    if (!(a.K_lo < a.K_hi && a.K_hi <= 0.0))
        usage_error("--K-range must satisfy LO < HI <= 0, got " + std::to_string(a.K_lo) + "," + std::to_string(a.K_hi));
    return a;
}

// eps values already in the CSV (first column), so a rerun resumes.
std::set<std::string> done_rows(const std::string& path) {
    std::set<std::string> done;
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line))
        if (!line.empty() && line[0] != 'e') done.insert(line.substr(0, line.find(',')));
    return done;
}

// Shortest text that reads back as exactly this double: a readable and exact resume key.
std::string key_of(double eps) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, eps);
    return std::string(buf, r.ptr);
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const Args a = parse(argc, argv);
        const auto done = done_rows(a.out);
        const bool fresh = done.empty() && !std::ifstream(a.out).good();
        std::ofstream csv(a.out, std::ios::app);
        if (!csv) throw std::runtime_error("cannot open " + a.out + " for appending");
        if (fresh)
            csv << "eps,n_orbits,never_impact,impact,escaped,area_never_impact,box_area,theory_eq_hovsetsize,steps\n"
                << std::flush;

        const long n = a.n_phi * a.n_K;
        std::vector<double> phi0(static_cast<std::size_t>(n)), K0(static_cast<std::size_t>(n));
        for (long i = 0; i < a.n_phi; ++i)
            for (long j = 0; j < a.n_K; ++j) {
                phi0[std::size_t(i * a.n_K + j)] = -kPi + (double(i) + 0.5) * 2 * kPi / double(a.n_phi);
                K0[std::size_t(i * a.n_K + j)] = a.K_lo + (double(j) + 0.5) * (a.K_hi - a.K_lo) / double(a.n_K);
            }
        std::vector<std::int8_t> status(static_cast<std::size_t>(n));
        const double box = 2 * kPi * (a.K_hi - a.K_lo);
        for (double eps : a.eps) {
            if (done.count(key_of(eps))) {
                std::cerr << "eps = " << key_of(eps) << ": already in " << a.out << ", skipped\n";
                continue;
            }
            const auto m = hovering::make_truncated_map(eps, a.Omega0, a.theta_w, a.tau0, a.tau1, a.lam);
            hovering::IterateOptions opt;
            opt.n_steps = a.steps;
            opt.exit_mask = (1u << int(hovering::Region::Beside)) | (1u << int(hovering::Region::Above));
            opt.stop_on_exit = true;
            opt.n_threads = a.threads;
            hovering::IterateOutput out;
            out.status = status.data();
            m.iterate(phi0.data(), K0.data(), n, opt, out);
            long ok = 0, exited = 0, escaped = 0;
            for (auto s : status) {
                ok += s == std::int8_t(hovering::Status::Ok);
                exited += s == std::int8_t(hovering::Status::Exited);
                escaped += s == std::int8_t(hovering::Status::Escaped);
            }
            const double theory = eps > 0 ? eps * (std::sin(a.theta_w) - a.theta_w * std::cos(a.theta_w)) /
                                                std::sin(0.5 * a.Omega0)
                                          : 0.0;
            char row[512];
            std::snprintf(row, sizeof row, "%s,%ld,%ld,%ld,%ld,%.10g,%.10g,%.10g,%ld\n", key_of(eps).c_str(), n, ok,
                          exited, escaped, box * double(ok) / double(n), box, theory, a.steps);
            csv << row << std::flush;  // on disk before the next eps starts
            std::cerr << row;
        }
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "hovering_sweep: " << e.what() << "\n";
        return 2;
    }
}
