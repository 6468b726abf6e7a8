// hovering_sweep: run a resolved sweep plan of hovering without Python.
//
//   hovering_sweep --plan PLAN.toml [--out FILE] [--threads N]
//
// A plan (docs/sweep-plan.md) is written by `python -m hovering plan SCENE.toml [-o PLAN.toml]
// [--quick]`, or by hand: every point's numbers are explicit, so this program reads it with type
// and range checks only and measures each point with the core's hovering_area, the same functions
// `python -m hovering scene` calls: the rows are the same doubles. Each finished point is appended
// to a checkpoint (JSON lines, the format of hovering.parallel.checkpoint; default: the plan's
// `checkpoint`, relative to the plan's folder) at once, fsync'd; a rerun, or `python -m hovering
// scene` on the same scene and file, skips the points already there. Two runs on one file share
// the work: a point one has written is neither computed nor written by the other.
//
// Exit status: 0 done (every point in the file), 2 bad input (the plan, the options, the file: one
// line saying what and where), 130 interrupted (Ctrl-C / SIGTERM: the points finished are kept).

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "hovering/build_info.hpp"
#include "hovering/sweep/plan.hpp"
#include "hovering/sweep/run.hpp"

namespace fs = std::filesystem;
using namespace hovering::sweep;

namespace {

std::atomic<bool> g_cancel{false};

extern "C" void on_signal(int) {
    g_cancel.store(true);
}

/// Text from a file (a plan's name and labels, a path, a message quoting them) as it is printed, one line:
/// control characters as '?', so that no escape sequence (ESC [ ...) from a file reaches the terminal.
std::string printable(const std::string& s) {
    std::string out = s;
    for (char& c : out) {
        const unsigned char u = static_cast<unsigned char>(c);
        if (u < 0x20 || u == 0x7f) c = '?';
    }
    return out;
}

/// Reports a running point's progress on a terminal about once a second (nothing when stderr is
/// redirected: a log gets one line per finished point).
class Ticker {
public:
    Ticker(std::string what, double total, const std::atomic<std::int64_t>& done)
        : what_(std::move(what)), total_(total), done_(done) {
        if (isatty(2)) thread_ = std::thread([this] { loop(); });
    }
    ~Ticker() {
        {
            std::lock_guard<std::mutex> lock(m_);
            stop_ = true;
        }
        cv_.notify_all();
        if (thread_.joinable()) {
            thread_.join();
            std::fprintf(stderr, "\r\033[K");
        }
    }

private:
    void loop() {
        const auto t0 = std::chrono::steady_clock::now();
        std::unique_lock<std::mutex> lock(m_);
        while (!cv_.wait_for(lock, std::chrono::seconds(1), [this] { return stop_; })) {
            const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            const double f = std::min(0.99, double(done_.load()) / total_);
            std::fprintf(stderr, "\r\033[K%s ~%2.0f%% %.0f s", what_.c_str(), 100 * f, s);
            std::fflush(stderr);
        }
    }
    std::string what_;
    double total_;
    const std::atomic<std::int64_t>& done_;
    std::mutex m_;
    std::condition_variable cv_;
    bool stop_ = false;
    std::thread thread_;
};

/// The checkpoint path of a run: --out, or the plan's own, relative to the plan's folder.
std::string output_path(const Plan& plan, const std::string& out) {
    if (!out.empty()) return out;
    if (plan.checkpoint.empty()) throw std::invalid_argument(plan.path + " names no checkpoint: give --out FILE");
    const fs::path c(plan.checkpoint);
    return c.is_absolute() ? c.string() : (fs::path(plan.path).parent_path() / c).string();
}

/// What wrote the points that follow: the core's build facts and this run's settings.
std::string provenance(int threads) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& f : hovering::build_info()) {
        if (f.number)
            j[f.name] = std::stoll(f.value);
        else
            j[f.name] = f.value;
    }
    const unsigned hw = std::thread::hardware_concurrency();
    j["program"] = "hovering_sweep";
    j["threads"] = threads > 0 ? unsigned(threads) : std::max(1u, hw);
    return j.dump();
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{
        "Run a resolved sweep plan of hovering (written by python -m hovering plan SCENE.toml) without "
        "Python: each point measured and appended to a resumable checkpoint.",
        "hovering_sweep"};
    std::string plan_path, out, scene;
    bool quick = false;
    int threads = 0;
    app.add_option("--plan", plan_path,
                   "Plan file (TOML) from python -m hovering plan, or written by hand "
                   "(docs/sweep-plan.md)");
    app.add_option("--out", out,
                   "Checkpoint file (JSON lines) to append the points to (default: the plan's checkpoint, relative to "
                   "the plan's folder); points already in it are skipped, and python -m hovering scene reads it");
    app.add_option("--threads", threads, "Worker threads, 0 = all cores")->check(CLI::Range(0, 4096));
    // Gone options, kept only to say what replaced them.
    app.add_option("--scene", scene)->group("");
    app.add_flag("--quick", quick)->group("");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    if (!scene.empty() || quick) {
        std::cerr << "hovering_sweep: " << (scene.empty() ? "--quick" : "--scene") << " is gone: hovering_sweep runs a "
                  << "resolved plan; write one with `python -m hovering plan " << (scene.empty() ? "SCENE.toml" : scene)
                  << (quick ? " --quick" : "") << " -o PLAN.toml`, then run `hovering_sweep --plan PLAN.toml`\n";
        return 2;
    }
    if (plan_path.empty()) {
        std::cerr
            << "hovering_sweep: --plan PLAN.toml is required (write one with python -m hovering plan SCENE.toml)\n";
        return 2;
    }

    try {
        // Everything is checked before the file is touched or anything is computed.
        const Plan plan = load_plan(plan_path);
        check_memory(plan);
        const std::string path = output_path(plan, out);
        {
            std::error_code ec;
            const fs::path p(path);
            if (fs::is_directory(p, ec))
                throw std::invalid_argument("--out must name a file, got the directory '" + path + "'");
            const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
            if (!fs::is_directory(dir, ec))
                throw std::invalid_argument("'" + path + "': the directory '" + dir.string() +
                                            "' does not exist (create it, or give --out)");
        }
        Checkpoint ckpt(path);
        if (!ckpt.torn().empty())
            std::cerr << "hovering_sweep: " << printable(path) << ": dropped " << ckpt.torn()
                      << ", left by an interrupted run; its point is recomputed\n";
        std::size_t todo = 0;
        for (const auto& p : plan.points) todo += !ckpt.done(p.key);
        const std::string name = printable(plan.name.empty() ? plan_path : plan.name);
        std::cerr << name << ": " << plan.points.size() << " points, " << plan.points.size() - todo << " already in "
                  << printable(path) << "\n";
        if (todo == 0) return 0;

        const std::string prov = provenance(threads);
        std::signal(SIGINT, on_signal);
        std::signal(SIGTERM, on_signal);
        std::size_t written = 0;
        for (std::size_t i = 0; i < plan.points.size(); ++i) {
            const PlanPoint& p = plan.points[i];
            if (ckpt.done(p.key)) continue;  // finished (by another run, meanwhile)
            std::string what = "[" + std::to_string(i + 1) + "/" + std::to_string(plan.points.size()) + "]";
            if (!p.label.empty()) what += " " + printable(p.label) + ",";
            what += " eps = " + format_number(plan.kind == "hovering_area" ? p.map.eps : p.system.eps);
            std::atomic<std::int64_t> done{0};
            PointRow row;
            {
                Ticker tick(what, point_work(plan, i), done);
                try {
                    row = run_point(plan, i, threads, &g_cancel, &done);
                } catch (const std::invalid_argument& e) {
                    throw std::invalid_argument(plan_path + ": points[" + std::to_string(i) + "]: " + e.what());
                }
            }
            if (row.interrupted || g_cancel.load()) {
                std::cerr << "hovering_sweep: interrupted during " << what << "; the " << written
                          << " point(s) finished in this run are in " << printable(path)
                          << " (rerun the same command to go on)\n";
                return 130;
            }
            const bool mine = ckpt.append(p.key, row.row, prov);  // on disk (fsync) before the next point starts
            written += mine;
            std::fprintf(stderr, "%s: |HOV| = %.6g +- %.2g (theory %.6g), %.1f s%s\n", what.c_str(), row.area,
                         row.error, row.theory, row.seconds, mine ? "" : " (another run wrote it first: kept theirs)");
        }
        return 0;
    } catch (const std::bad_alloc&) {
        std::cerr << "hovering_sweep: out of memory (reduce the plan's samples or --threads)\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "hovering_sweep: " << printable(e.what()) << "\n";
        return 2;
    }
}
