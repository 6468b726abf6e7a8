// Running a plan's points and the checkpoint file; see run.hpp and docs/sweep-plan.md.
#include "hovering/sweep/run.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <nlohmann/json.hpp>

#include "hovering/analysis/hovering_area.hpp"
#include "hovering/sweep/plan_build.hpp"

namespace hovering::sweep {

namespace {

using json = nlohmann::json;

/// A double as a checkpoint line holds it: a JSON number, or the string naming a non-finite one.
json jnum(double x) {
    if (std::isnan(x)) return "NaN";
    if (std::isinf(x)) return x > 0 ? "Infinity" : "-Infinity";
    return x;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// The row fields of a hovering_area estimate (hovering.parallel.checkpoint reads the same names).
json area_row(const HoveringAreaResult& h) {
    return {{"area", jnum(h.area)},
            {"error", jnum(h.error)},
            {"sampling_error", jnum(h.sampling_error)},
            {"iteration_error", jnum(h.iteration_error)},
            {"area_N4", jnum(h.area_quarter)},
            {"area_N2", jnum(h.area_half)},
            {"area_both_sides", jnum(h.area_both_sides)},
            {"impact_fraction_F0", jnum(h.impact_fraction_F0)},
            {"floor_touched", h.floor_touched},
            {"unresolved", h.unresolved},
            {"n_samples", h.n_samples},
            {"K_low", jnum(h.K_low)}};
}

HoveringAreaOptions options(const PlanPoint& p, int n_threads, const std::atomic<bool>* cancel,
                            std::atomic<std::int64_t>* progress, double K_low, bool keep) {
    HoveringAreaOptions o;
    o.n_steps = p.n_steps;
    o.samples = p.samples;
    o.seed = p.seed;
    o.K_low = K_low;
    o.n_threads = n_threads;
    o.cancel = cancel;
    o.progress = progress;
    o.keep_points = keep;
    return o;
}

}  // namespace

double point_work(const Plan& plan, std::size_t i) {
    const PlanPoint& p = plan.points.at(i);
    return 2.0 * double(p.samples) * double(p.n_steps) * double(1 + p.models.size());
}

PointRow run_point(const Plan& plan, std::size_t i, int n_threads, const std::atomic<bool>* cancel,
                   std::atomic<std::int64_t>* progress) {
    const PlanPoint& p = plan.points.at(i);
    const auto t0 = std::chrono::steady_clock::now();
    PointRow out;
    json row;
    HoveringAreaResult h;
    if (plan.kind == "hovering_area") {
        h = hovering_area(build_map(p.map), options(p, n_threads, cancel, progress, p.K_low, false));
        row = area_row(h);
    } else {
        const FlowSystem s = build_system(p.system, p.system.eps), s0 = build_system(p.system, 0.0);
        const FlowMap m = build_flow_map(s, p.h, build_options(p.integrator, s));
        const FlowMap m0 = build_flow_map(s0, p.h, build_options(p.integrator, s0));
        h = hovering_area(m, m0, options(p, n_threads, cancel, progress, p.K_low, !p.models.empty()));
        row = area_row(h);
        row["b1"] = jnum(p.b1);
        json models = json::object();
        for (const ModelSpec& ms : p.models) {
            if (cancel && cancel->load()) break;
            const HoveringAreaResult mh =
                hovering_area(build_model(ms), options(p, n_threads, cancel, progress, ms.K_low, true));
            out.interrupted = out.interrupted || mh.interrupted;
            // A model sampling another box (its band is shallower) classifies other points: no agreement.
            double agree = std::numeric_limits<double>::quiet_NaN();
            if (ms.K_low == p.K_low) {
                std::int64_t same = 0;
                for (std::size_t k = 0; k < mh.hovering.size(); ++k) same += mh.hovering[k] == h.hovering[k];
                agree = double(same) / double(mh.hovering.size());
            }
            models[ms.name] = {
                {"area", jnum(mh.area)}, {"error", jnum(mh.error)}, {"agree", jnum(agree)}, {"K_low", jnum(ms.K_low)}};
        }
        row["models"] = models;
    }
    out.interrupted = out.interrupted || h.interrupted || (cancel && cancel->load());
    out.area = h.area;
    out.error = h.error;
    out.theory = p.theory;
    out.seconds = seconds_since(t0);
    row["theory"] = jnum(p.theory);
    row["seconds"] = out.seconds;
    out.row = row.dump();
    return out;
}

// ------------------------------------------------------------------ the checkpoint file

namespace {

/// Largest checkpoint read: a line is a few hundred bytes (a flow point with its models' tables
/// some 20 KB), so 1 GiB holds far more points than a sweep has.
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t(1) << 30;
/// Longest line read (a key holds a model's tables of at most 100000 heights: ~10 MB).
constexpr std::size_t kMaxLine = std::size_t(16) << 20;

std::string sys_error(const std::string& what, int err) {
    return what + ": " + std::strerror(err);
}

/// Why a complete line is not a record of a checkpoint ("" if it is one); `header`: the first line.
std::string check_line(const std::string& line, bool header, std::string& key) {
    const json j = json::parse(line, nullptr, false);
    const std::string not_header =
        "the first line is not the header {\"format\": \"hovering-checkpoint\", \"version\": " +
        std::to_string(kCheckpointVersion) + "}: ";
    if (header && (j.is_discarded() || !j.is_object())) return not_header + "another program's file";
    if (j.is_discarded()) return "not a line of JSON";
    if (!j.is_object()) return "not a JSON object";
    if (header) {
        const auto f = j.find("format");
        const auto v = j.find("version");
        if (j.size() != 2 || f == j.end() || v == j.end() || *f != "hovering-checkpoint")
            return not_header + (j.contains("key") && j.contains("row")
                                     ? "a checkpoint of an older hovering, whose points were keyed otherwise"
                                     : "another program's file");
        if (!v->is_number_integer() || *v != kCheckpointVersion)
            return "a checkpoint of version " + v->dump() + "; this program reads version " +
                   std::to_string(kCheckpointVersion);
        return "";
    }
    if (j.size() == 1 && j.contains("provenance") && j["provenance"].is_object()) return "";
    const auto k = j.find("key"), r = j.find("row");
    if (j.size() == 2 && k != j.end() && r != j.end() && k->is_object() && r->is_object()) {
        key = k->dump();
        return "";
    }
    return "neither a point {\"key\": {...}, \"row\": {...}} nor a provenance record {\"provenance\": {...}}";
}

class Lock {
public:
    Lock(int fd, int how, const std::string& path) : fd_(fd) {
        while (::flock(fd_, how) != 0) {
            if (errno != EINTR) throw std::runtime_error(sys_error("cannot lock " + path, errno));
        }
    }
    ~Lock() { ::flock(fd_, LOCK_UN); }
    Lock(const Lock&) = delete;
    Lock& operator=(const Lock&) = delete;

private:
    int fd_;
};

}  // namespace

Checkpoint::Checkpoint(const std::string& path) : path_(path) {
    struct stat pre;
    if (::stat(path.c_str(), &pre) == 0 && !S_ISREG(pre.st_mode))  // a FIFO or a device would be read forever
        throw std::invalid_argument(path + " is not a regular file (a checkpoint)");
    fd_ = ::open(path.c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0666);
    if (fd_ < 0 && (errno == EACCES || errno == EROFS)) {
        read_only_ = errno;
        fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    }
    if (fd_ < 0) throw std::invalid_argument(sys_error("cannot open " + path, errno));
    struct stat st;
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd_);
        throw std::invalid_argument(path + " is not a regular file (a checkpoint)");
    }
    try {
        Lock lock(fd_, read_only_ ? LOCK_SH : LOCK_EX, path_);
        scan(!read_only_);
    } catch (...) {
        ::close(fd_);
        throw;
    }
}

Checkpoint::~Checkpoint() {
    ::close(fd_);
}

void Checkpoint::scan(bool may_cut) {
    struct stat st;
    if (::fstat(fd_, &st) != 0) throw std::runtime_error(sys_error("cannot read " + path_, errno));
    const std::uintmax_t size = std::uintmax_t(st.st_size);
    if (size > kMaxFileBytes)
        throw std::invalid_argument(path_ + " has " + std::to_string(size) + " bytes; allowed: at most " +
                                    std::to_string(kMaxFileBytes) + " for a checkpoint (use another --out)");
    if (size <= offset_) return;
    std::string line;
    std::uintmax_t pos = offset_;
    std::vector<char> buf(1 << 16);
    while (pos < size) {
        const ssize_t n = ::pread(fd_, buf.data(), std::min<std::uintmax_t>(buf.size(), size - pos), off_t(pos));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw std::runtime_error(sys_error("cannot read " + path_, errno));
        if (n == 0) break;
        for (ssize_t k = 0; k < n; ++k) {
            const char c = buf[std::size_t(k)];
            if (c != '\n') {
                if (line.size() == kMaxLine)
                    throw std::invalid_argument(path_ + " line " + std::to_string(lines_ + 1) + " is longer than " +
                                                std::to_string(kMaxLine) +
                                                " bytes: not a checkpoint line (use another --out)");
                line.push_back(c);
                continue;
            }
            std::string key;
            const std::string why = check_line(line, lines_ == 0, key);
            if (!why.empty())
                throw std::invalid_argument(
                    path_ + " line " + std::to_string(lines_ + 1) + ": " + why +
                    (lines_ == 0 ? "; use another --out, or move the file away"
                                 : ": the file was edited or damaged; fix or remove that line, or use another --out"));
            if (!key.empty()) keys_.insert(key);
            ++lines_;
            offset_ += line.size() + 1;
            line.clear();
        }
        pos += std::uintmax_t(n);
    }
    if (!line.empty() && may_cut) {
        // A line without its newline: a run killed while writing it. Cut it off (its point is
        // recomputed), or the next line would be glued to it.
        if (::ftruncate(fd_, off_t(offset_)) != 0 || ::fsync(fd_) != 0)
            throw std::runtime_error(sys_error("cannot cut the torn last line off " + path_, errno));
        torn_ = "a last line of " + std::to_string(line.size()) + " bytes without its newline";
    }
}

bool Checkpoint::done(const std::string& key) {
    Lock lock(fd_, LOCK_SH, path_);
    scan(false);
    return keys_.count(key) > 0;
}

void Checkpoint::write_all(const std::string& text, const char* what) {
    if (read_only_) throw std::runtime_error(sys_error("cannot write " + path_, read_only_));
    struct stat st;
    if (::fstat(fd_, &st) != 0) throw std::runtime_error(sys_error("cannot write " + path_, errno));
    std::size_t done = 0;
    int err = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            err = n < 0 ? errno : ENOSPC;
            break;
        }
        done += std::size_t(n);
    }
    if (!err && ::fsync(fd_) != 0) err = errno;
    if (err) {
        if (::ftruncate(fd_, st.st_size) == 0) ::fsync(fd_);  // no half line left behind
        const std::string why = err == ENOSPC || err == EDQUOT || err == EFBIG
                                    ? "no space left (" + std::string(std::strerror(err)) + ")"
                                    : std::string(std::strerror(err));
        throw std::runtime_error(std::string("writing ") + what + " to " + path_ + " failed: " + why +
                                 "; the lines written before are kept");
    }
}

bool Checkpoint::append(const std::string& key, const std::string& row, const std::string& provenance) {
    if (read_only_) throw std::runtime_error(sys_error("cannot write " + path_, read_only_));
    Lock lock(fd_, LOCK_EX, path_);
    scan(true);  // what other runs appended meanwhile (a torn tail of a crashed one is cut off)
    if (keys_.count(key)) return false;
    std::string text;
    if (lines_ == 0) text += json({{"format", "hovering-checkpoint"}, {"version", kCheckpointVersion}}).dump() + "\n";
    if (!provenance_written_) text += "{\"provenance\":" + provenance + "}\n";
    text += "{\"key\":" + key + ",\"row\":" + row + "}\n";
    write_all(text, "a point");
    provenance_written_ = true;
    keys_.insert(key);
    offset_ += text.size();
    for (char c : text) lines_ += c == '\n';
    return true;
}

}  // namespace hovering::sweep
