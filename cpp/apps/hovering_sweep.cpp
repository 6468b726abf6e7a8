// hovering_sweep: run the sweep scenes (TOML) of hovering without Python.
//
//   hovering_sweep --scene FILE.toml [--quick] [--out CSV] [--threads N]
//
// Reads a scene of kind "hovering_area" (|HOV| of the truncated map against eps, per series) or
// "flow_hovering_area" (|HOV| of the full flow against eps) with the schema and messages of
// `python -m hovering scene`, measures each point as Python does (the same samples; truncated points
// are Python's bit for bit), and appends one CSV row per point, flushed as it finishes. A row holds
// the results, then every parameter that changes them (as shortest round-trip text); a rerun skips
// the points whose parameters are already in the file, so an interrupted sweep (Ctrl-C, a kill, a
// crash) loses only the point it was computing, and one file can hold several sweeps. A file with
// another header is refused rather than mixed, and a last row torn by a kill is dropped. The file
// resumed from is untrusted (docs/threat-model.md): a regular file of at most 1 GiB whose lines are
// at most 64 KiB, checked before they are read.
//
// Lines starting with '#' are comments: "# provenance: {...}" (one line of JSON: the core's build
// facts, hovering::build_info, plus the run's threads and seed) comes before the header of a new
// file, and again before the rows of a later run whose facts differ, so every row is preceded by
// the facts of the run that wrote it. A run holds an exclusive lock (flock) on the file from
// reading it to its last row; a second run on the same file meanwhile is refused at once with a
// message (rather than queued: a sweep takes minutes to hours, and a run that silently waits that
// long looks hung; started twice by mistake, the second run would have nothing left to do).

#include <CLI/CLI.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <atomic>
#include <charconv>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <new>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "hovering/build_info.hpp"
#include "hovering/scene/sweep_run.hpp"
#include "hovering/scene/sweep_scene.hpp"

namespace fs = std::filesystem;
using namespace hovering::scene;

namespace {

std::atomic<bool> g_cancel{false};

extern "C" void on_signal(int) { g_cancel.store(true); }

std::string num(double x) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

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

std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
    return s;
}

/// What the output file holds, as far as resuming is concerned.
struct Existing {
    bool write_header = true;   ///< new, empty, or only comments and a torn header
    bool torn = false;          ///< its last line is incomplete or invalid and must go
    std::uintmax_t keep = 0;    ///< bytes to keep when torn
    std::string torn_note;      ///< what was wrong with the dropped line
    std::string provenance;     ///< its last complete provenance comment line ("" if none)
    std::vector<std::vector<std::string>> params;  ///< parameter fields of its complete rows
};

/// The comment line that records what wrote the rows after it.
const std::string kProvenance = "# provenance: ";

/// Why this line is not a row under `header` ("" if it is one); fills params when it is.
std::string check_row(const std::string& line, std::size_t n_results, std::size_t n_columns,
                      std::vector<std::string>& params) {
    const auto f = split(line);
    if (f.size() != n_columns)
        return "it has " + std::to_string(f.size()) + " fields, expected " + std::to_string(n_columns);
    for (std::size_t c = 0; c < n_results; ++c) {
        double d = 0;
        const char* b = f[c].data();
        const char* e = b + f[c].size();
        const auto r = std::from_chars(b, e, d);
        if (f[c].empty() || r.ec != std::errc() || r.ptr != e)
            return "field " + std::to_string(c + 1) + " ('" + f[c] + "') is not a number";
    }
    params.assign(f.begin() + std::ptrdiff_t(n_results), f.end());
    return "";
}

/// Largest CSV resumed from: a row is ~300 bytes, a sweep scene at most 36 x 200 points (2 MB), so
/// 1 GiB holds hundreds of sweeps; its rows' fields then take a few GiB of memory.
constexpr std::uintmax_t kMaxCsvBytes = std::uintmax_t(1) << 30;
/// Longest CSV line read: a header or row has a few dozen fields of at most ~25 characters.
constexpr std::size_t kMaxLine = 1 << 16;

/// One line of `in` without its newline (complete: it had one), refused beyond kMaxLine bytes
/// before more is read. False at the end of the file.
bool read_line(std::istream& in, std::string& line, bool& complete, const std::string& path, long lineno) {
    line.clear();
    complete = false;
    std::streambuf* buf = in.rdbuf();
    for (int c = buf->sbumpc(); c != std::char_traits<char>::eof(); c = buf->sbumpc()) {
        if (c == '\n') {
            complete = true;
            return true;
        }
        if (line.size() == kMaxLine)
            throw std::runtime_error(path + " line " + std::to_string(lineno) + " is longer than " +
                                     std::to_string(kMaxLine) + " bytes: not a row of hovering_sweep (use another --out)");
        line.push_back(char(c));
    }
    return !line.empty();
}

/// Read the output file: refuse a foreign header or a damaged row inside it, find a torn tail.
/// The file is untrusted: a regular file of at most kMaxCsvBytes, lines of at most kMaxLine.
Existing scan(const std::string& path, const std::string& header, std::size_t n_results) {
    Existing ex;
    std::error_code ec;
    if (!fs::exists(path, ec)) return ex;
    if (!fs::is_regular_file(path, ec)) throw std::runtime_error(path + " is not a regular file (to resume from it)");
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) throw std::runtime_error("cannot read " + path + " (to resume from it): " + ec.message());
    if (size > kMaxCsvBytes)
        throw std::runtime_error(path + " has " + std::to_string(size) + " bytes; allowed: at most " +
                                 std::to_string(kMaxCsvBytes) + " to resume from (use another --out)");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read " + path + " (to resume from it)");
    const std::size_t n_columns = split(header).size();
    std::string line, bad_note;
    std::uintmax_t offset = 0;
    long lineno = 0, bad_line = 0;
    bool header_seen = false, complete = false;
    while (read_line(in, line, complete, path, lineno + 1)) {
        ++lineno;
        if (bad_line)
            throw std::runtime_error(path + " line " + std::to_string(bad_line) + " is not a valid row (" + bad_note +
                                     ") and rows follow it, so it is not a row torn by an interrupted run: the "
                                     "file was edited or damaged. Fix or remove that line, or use another --out.");
        if (complete && !line.empty() && line[0] == '#') {
            if (line.compare(0, kProvenance.size(), kProvenance) == 0) ex.provenance = line;
        } else if (!header_seen) {
            if (!complete && (header.compare(0, line.size(), line) == 0 || line[0] == '#')) {
                ex.torn = true;  // killed while writing the header (or a comment): write it again
                ex.keep = offset;
                ex.torn_note = "an incomplete header";
            } else if (line != header) {
                throw std::runtime_error(path + " does not have the header of this scene kind's rows (another kind "
                                         "of scene, an older version or another program's file): use another --out "
                                         "or move it away.\n  expected: " + header + "\n  found:    " + line);
            } else {
                header_seen = true;
                ex.write_header = false;
            }
        } else {
            std::vector<std::string> p;
            const std::string why = complete ? check_row(line, n_results, n_columns, p) : "no newline at its end";
            if (why.empty()) {
                ex.params.push_back(std::move(p));
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

/// The output CSV, held under an exclusive lock (flock) for the whole run, whose every appended
/// line is on disk (written, flushed, fsync'd) when line() returns: a crash or power cut after it
/// cannot lose that row, and a failed write (a full disk) is cut back off, leaving no half line.
class LockedCsv {
public:
    /// Open (creating) and lock `path`; refuse at once if another run holds the lock.
    explicit LockedCsv(const std::string& path) : path_(path) {
        fd_ = ::open(path.c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0666);
        if (fd_ < 0 && (errno == EACCES || errno == EROFS)) {
            // A read-only file can still tell that its sweep is complete (shared lock: no run writes it
            // meanwhile); writing to it fails in line().
            read_only_ = errno;
            fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
        }
        if (fd_ < 0) throw std::runtime_error("cannot open " + path + " for appending: " + std::strerror(errno));
        if (::flock(fd_, (read_only_ ? LOCK_SH : LOCK_EX) | LOCK_NB) != 0) {
            const int err = errno;
            ::close(fd_);
            if (err == EWOULDBLOCK)
                throw std::runtime_error(path + " is being written by another hovering_sweep run (it holds the file's "
                                         "lock): wait for that run to finish and rerun this command (it resumes), "
                                         "or give another --out");
            throw std::runtime_error("cannot lock " + path + ": " + std::strerror(err));
        }
    }
    ~LockedCsv() { ::close(fd_); }  // releases the lock
    LockedCsv(const LockedCsv&) = delete;
    LockedCsv& operator=(const LockedCsv&) = delete;
    /// Cut the file to `size` bytes (a torn last line).
    void truncate(std::uintmax_t size) {
        writable();
        if (::ftruncate(fd_, off_t(size)) != 0 || ::fsync(fd_) != 0)
            throw std::runtime_error("cannot cut the torn row off " + path_ + ": " + std::strerror(errno));
    }
    /// Append text and a newline, and make them durable; `what` names it in the error message.
    void line(const std::string& text, const char* what) {
        writable();
        const std::string l = text + "\n";
        struct stat st;
        if (::fstat(fd_, &st) != 0) fail(what, errno, -1);
        std::size_t done = 0;
        while (done < l.size()) {
            const ssize_t n = ::write(fd_, l.data() + done, l.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) fail(what, n < 0 ? errno : ENOSPC, st.st_size);
            done += std::size_t(n);
        }
        if (::fsync(fd_) != 0) fail(what, errno, st.st_size);
    }

private:
    void writable() const {
        if (read_only_)
            throw std::runtime_error("cannot write " + path_ + ": " + std::strerror(read_only_));
    }
    [[noreturn]] void fail(const char* what, int err, off_t size) {
        if (size >= 0 && ::ftruncate(fd_, size) == 0) ::fsync(fd_);  // no half line left behind
        const std::string why = err == ENOSPC || err == EDQUOT || err == EFBIG
                                    ? "no space left (" + std::string(std::strerror(err)) + ")"
                                    : std::string(std::strerror(err));
        throw std::runtime_error(std::string("writing ") + what + " to " + path_ + " failed: " + why +
                                 "; the rows written before are kept");
    }
    std::string path_;
    int fd_ = -1;
    int read_only_ = 0;  ///< errno of opening for writing when only reading was possible
};

/// The default output: the scene's figure path with the extension .csv.
std::string default_out(const SweepScene& s) { return fs::path(s.output).replace_extension(".csv").string(); }

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Run a sweep scene (kind hovering_area or flow_hovering_area) of hovering without Python: one CSV "
                 "row per point, resumable.",
                 "hovering_sweep"};
    std::string scene_path, out;
    bool quick = false;
    int threads = 0;
    app.add_option("--scene", scene_path, "Scene file (TOML) of kind hovering_area or flow_hovering_area")
        ->required()
        ->check(CLI::ExistingFile);
    app.add_flag("--quick", quick, "Counts divided by 50 (as python -m hovering scene --quick)");
    app.add_option("--out", out,
                   "CSV file to append rows to (default: the scene's output with the extension .csv); rows already "
                   "in it with the same parameters are skipped. The run locks it: a second run on the same file "
                   "meanwhile is refused");
    app.add_option("--threads", threads, "Worker threads, 0 = all cores")->check(CLI::Range(0, 4096));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }

    try {
        // Everything is checked before the file is touched or anything is computed.
        const SweepScene scene = load_sweep_scene(scene_path);
        check_runnable(scene);
        if (out.empty()) out = default_out(scene);
        {
            std::error_code ec;
            const fs::path p(out);
            if (fs::is_directory(p, ec)) throw std::invalid_argument("--out must name a file, got the directory '" + out + "'");
            const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
            if (!fs::is_directory(dir, ec))
                throw std::invalid_argument("--out '" + out + "': the directory '" + dir.string() +
                                            "' does not exist (create it, or give --out)");
        }
        const SweepCounts counts = sweep_counts(scene, quick);
        const auto points = sweep_points(scene);
        const auto results = result_columns(scene);
        std::vector<std::string> columns = results;
        for (const auto& [name, value] : point_parameters(scene, points.front(), counts)) columns.push_back(name);
        const std::string header = join(columns);

        LockedCsv csv(out);  // from here to the last row, no other run writes this file
        const Existing ex = scan(out, header, results.size());
        // What wrote the rows that follow: the core's build facts and this run's settings.
        std::vector<hovering::BuildFact> facts = hovering::build_info();
        const unsigned hw = std::thread::hardware_concurrency();
        facts.push_back({"threads", std::to_string(threads > 0 ? unsigned(threads) : std::max(1u, hw)), true});
        facts.push_back({"seed", std::to_string(scene.seed), true});
        const std::string provenance = kProvenance + hovering::facts_json(facts);
        // A set: the file's rows are untrusted in number too (a scan per point would be quadratic).
        const std::set<std::vector<std::string>> finished(ex.params.begin(), ex.params.end());
        std::vector<std::size_t> todo;
        for (std::size_t i = 0; i < points.size(); ++i) {
            std::vector<std::string> key;
            for (const auto& [name, value] : point_parameters(scene, points[i], counts)) key.push_back(value);
            if (!finished.count(key)) todo.push_back(i);
        }
        std::cerr << scene.name << ": " << points.size() << " points (" << counts.n_steps << " steps, "
                  << counts.samples << " samples each), " << points.size() - todo.size() << " already in " << out
                  << "\n";
        if (ex.torn) {
            csv.truncate(ex.keep);
            std::cerr << "hovering_sweep: " << out << ": dropped a torn row (" << ex.torn_note
                      << "), left by an interrupted run; it is recomputed if requested\n";
        }
        if (todo.empty()) return 0;
        if (ex.provenance != provenance) csv.line(provenance, "the provenance comment");
        if (ex.write_header) csv.line(header, "the header");

        std::signal(SIGINT, on_signal);
        std::signal(SIGTERM, on_signal);
        std::size_t k = 0;
        for (std::size_t i : todo) {
            const SweepPoint& p = points[i];
            ++k;
            std::string what = "[" + std::to_string(k) + "/" + std::to_string(todo.size()) + "]";
            if (scene.kind == "hovering_area") what += " " + scene.series[p.series].label + ",";
            what += " eps = " + num(p.eps);
            std::atomic<std::int64_t> done{0};
            SweepRow row;
            {
                const bool onset = scene.kind == "flow_hovering_area" &&
                                   std::find(scene.models.begin(), scene.models.end(), "onset") != scene.models.end();
                Ticker tick(what, 2.0 * double(counts.samples) * double(counts.n_steps) * (onset ? 2 : 1), done);
                row = run_point(scene, p, counts, threads, &g_cancel, &done);
            }
            if (row.interrupted || g_cancel.load()) {
                std::cerr << "hovering_sweep: interrupted during " << what << "; the " << k - 1
                          << " point(s) finished in this run are in " << out << " (rerun the same command to go on)\n";
                return 130;
            }
            std::string line;
            for (const auto& [name, v] : row.values) line += (line.empty() ? "" : ",") + num(v);
            for (const auto& [name, v] : point_parameters(scene, p, counts)) line += "," + v;
            csv.line(line, "a row");  // on disk (fsync) before the next point starts
            double area = 0, err = 0, theory = 0, secs = 0;
            for (const auto& [name, v] : row.values) {
                if (name == "area") area = v;
                if (name == "error") err = v;
                if (name == "theory") theory = v;
                if (name == "seconds") secs = v;
            }
            std::fprintf(stderr, "%s: |HOV| = %.6g +- %.2g (theory %.6g), %.1f s\n", what.c_str(), area, err, theory, secs);
        }
        return 0;
    } catch (const std::bad_alloc&) {
        std::cerr << "hovering_sweep: out of memory (reduce the scene's samples or --threads)\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "hovering_sweep: " << e.what() << "\n";
        return 2;
    }
}
