// Running a plan's points and the checkpoint file; see run.hpp and docs/sweep-plan.md.
#include "hovering/sweep/run.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "hovering/analysis/hovering_area.hpp"
#include "hovering/sweep/json_number.hpp"
#include "hovering/sweep/plan_build.hpp"

namespace hovering::sweep {

namespace {

using json = nlohmann::json;


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

std::uintmax_t memory_budget() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return std::uintmax_t(1) << 35;  // 64 GiB where the system does not say
    return std::uintmax_t(pages) * std::uintmax_t(page) / 2;
}

void check_memory(const Plan& plan, std::uintmax_t budget) {
    for (std::size_t i = 0; i < plan.points.size(); ++i) {
        const PlanPoint& p = plan.points[i];
        // A flow point with models keeps its samples' outcomes while the models run theirs.
        const double per_sample = kBytesPerSample * (p.models.empty() ? 1 : 2);
        const double need = per_sample * double(p.samples);
        if (need > double(budget)) {
            char gib[64];
            std::snprintf(gib, sizeof gib, "%.3g GiB, more than %.3g GiB", need / double(1 << 30),
                          double(budget) / double(1 << 30));
            throw std::invalid_argument((plan.path.empty() ? std::string("plan") : plan.path) + ": points[" +
                                        std::to_string(i) + "].samples = " + std::to_string(p.samples) + " needs " +
                                        gib + " (half of this machine's memory): allowed: at most " +
                                        std::to_string(std::uintmax_t(double(budget) / per_sample)) + " samples here");
        }
    }
}

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

/// Deepest nesting of arrays and objects in a line (hovering.parallel.checkpoint reads no deeper:
/// hovering._untrusted.MAX_TREE_DEPTH). Deeper, dumping or destroying a value would recurse once
/// per level: a line of a million '[' crashed the program.
constexpr std::size_t kMaxDepth = 100;
/// Longest field path a message shows (a deep one is cut in the middle).
constexpr std::size_t kMaxField = 120;

/// At most n bytes of s, bytes outside printable ASCII as '?' (a message is one clean line).
std::string clip(const std::string& s, std::size_t n = 60) {
    std::string out;
    for (std::size_t i = 0; i < s.size() && i < n; ++i) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        out.push_back(c >= 0x20 && c < 0x7f ? char(c) : '?');
    }
    return s.size() > n ? out + "..." : out;
}

/// A value as a message shows it (its JSON, clipped).
std::string show(const json& v) {
    return clip(v.dump());
}

/// Checks one line of JSON while it is parsed (nlohmann's SAX interface, iterative: no recursion
/// whatever the nesting), keeping the path to the value being read so that every refusal names
/// its field, as ``key.map.eps`` or ``row.models[2]``: nesting deeper than kMaxDepth, a name twice
/// in one object, an integer beyond 64 bits, a number beyond a double, and any syntax error
/// (invalid UTF-8 included). The lines hovering.parallel.checkpoint refuses, refused alike.
class LineCheck {
public:
    using string_t = json::string_t;

    bool null() { return value(); }
    bool boolean(bool) { return value(); }
    bool number_integer(json::number_integer_t) { return value(); }
    bool number_unsigned(json::number_unsigned_t) { return value(); }
    bool number_float(json::number_float_t x, const string_t& text) {
        if (!value()) return false;
        // An integer beyond 64 bits reaches here as a double: another number than the text's.
        if (text.find_first_of(".eE") == string_t::npos)
            return fail("the integer " + clip(text, 40) + " is beyond 64 bits");
        if (!std::isfinite(x)) return fail("the number " + clip(text, 40) + " is beyond the range of a double");
        return true;
    }
    bool string(string_t&) { return value(); }
    bool binary(json::binary_t&) { return value(); }
    bool start_object(std::size_t) { return value() && open(true); }
    bool key(string_t& k) {
        Frame& f = stack_.back();
        f.key = k;
        f.has_key = true;
        if (!f.keys.insert(k).second) return fail("the name '" + clip(k, 40) + "' twice in one object");
        return true;
    }
    bool end_object() {
        stack_.pop_back();
        return true;
    }
    bool start_array(std::size_t) { return value() && open(false); }
    bool end_array() {
        stack_.pop_back();
        return true;
    }
    bool parse_error(std::size_t position, const std::string&, const json::exception& e) {
        // "[json.exception.parse_error.101] parse error at line 1, column 13: syntax error while
        // parsing value - invalid literal; last read: '...'": the middle, without the text read
        // (it may be megabytes, or bytes that are not UTF-8).
        std::string what = e.what();
        // A value that does not parse is the next element of its array (no callback counted it).
        if (what.find("while parsing value") != std::string::npos || what.find("number overflow") != std::string::npos)
            value();
        if (const auto b = what.find("] "); b != std::string::npos) what = what.substr(b + 2);
        if (const auto c = what.find(": "); what.rfind("parse error", 0) == 0 && c != std::string::npos)
            what = what.substr(c + 2);
        if (const auto l = what.find("; last read"); l != std::string::npos) what = what.substr(0, l);
        if (what.rfind("syntax error while parsing ", 0) == 0) {  // "... value - invalid literal"
            const auto d = what.find(" - ");
            what = d == std::string::npos ? what.substr(27) : what.substr(d + 3);
        }
        why_ = "not a line of JSON: " + clip(what, 160) + " at byte " + std::to_string(position) + ", in " + field();
        return false;
    }

    /// Why the line was refused ("" if it was not).
    const std::string& why() const { return why_; }

private:
    struct Frame {
        bool object = false;
        bool has_key = false;
        std::string key;
        long index = -1;
        std::set<std::string> keys;
    };

    /// A value starts: in an array, it is the next element.
    bool value() {
        if (!stack_.empty() && !stack_.back().object) ++stack_.back().index;
        return true;
    }
    bool open(bool object) {
        if (stack_.size() >= kMaxDepth)
            return fail("not a line of JSON: nested deeper than " + std::to_string(kMaxDepth) + " levels");
        Frame f;
        f.object = object;
        stack_.push_back(std::move(f));
        return true;
    }
    bool fail(const std::string& why) {
        why_ = why.rfind("not a line of JSON", 0) == 0 ? why + ", in " + field() : field() + ": " + why;
        return false;
    }
    std::string field() const {
        std::string at;
        for (const Frame& f : stack_) {
            if (f.object) {
                if (!f.has_key) break;
                at += (at.empty() ? "" : ".") + clip(f.key, 40);
            } else if (f.index >= 0) {
                at += "[" + std::to_string(f.index) + "]";
            }
        }
        if (at.empty()) return "the line";
        return at.size() <= kMaxField ? at
                                      : at.substr(0, kMaxField / 2) + " ... " + at.substr(at.size() - kMaxField / 2);
    }

    std::vector<Frame> stack_;
    std::string why_;
};

/// The names of an object's fields, for a message.
std::string names(const json& j) {
    std::string out;
    std::size_t n = 0;
    for (const auto& [k, v] : j.items()) {
        (void)v;
        if (n++ == 8) return out + ", ...";
        out += (out.empty() ? "'" : ", '") + clip(k, 40) + "'";
    }
    return out.empty() ? "none" : out;
}

/// What a JSON value is, for a message.
std::string kind(const json& v) {
    if (v.is_object()) return "an object";
    if (v.is_array()) return "an array";
    if (v.is_string()) return "a string " + show(v);
    if (v.is_boolean()) return "a boolean " + show(v);
    if (v.is_null()) return "null";
    return "a number " + show(v);
}

/// Why a complete line is not a record of a checkpoint ("" if it is one); `header`: the first line.
/// Every refusal names the field (or says the line as a whole is not JSON, and where).
std::string check_line(const std::string& line, bool header, std::string& key) {
    if (line.rfind("\xEF\xBB\xBF", 0) == 0)  // nlohmann skips a byte-order mark; Python's reader refuses it
        return "not a line of JSON: a byte-order mark (U+FEFF) at byte 0, in the line";
    const std::string not_header =
        "the first line is not the header {\"format\": \"hovering-checkpoint\", \"version\": " +
        std::to_string(kCheckpointVersion) + "}: ";
    LineCheck check;
    if (!json::sax_parse(line, &check) || !check.why().empty()) {
        const std::string why = check.why().empty() ? "not a line of JSON" : check.why();
        return header ? not_header + "another program's file (" + why + ")" : why;
    }
    const json j = json::parse(line, nullptr, false);
    if (j.is_discarded())
        return header ? not_header + "another program's file (not a line of JSON)" : "not a line of JSON";
    if (!j.is_object())
        return header ? not_header + "another program's file (the line is " + kind(j) + ")"
                      : "not a JSON object: the line is " + kind(j);
    if (header) {
        const auto f = j.find("format");
        const auto v = j.find("version");
        if (j.size() != 2 || f == j.end() || v == j.end() || *f != "hovering-checkpoint")
            return not_header + (j.contains("key") && j.contains("row")
                                     ? "a checkpoint of an older hovering, whose points were keyed otherwise"
                                     : "another program's file (fields: " + names(j) +
                                           (f != j.end() ? "; format = " + show(*f) : std::string()) + ")");
        if (!v->is_number_integer() || *v != kCheckpointVersion)
            return "a checkpoint of version " + show(*v) + " (its header's 'version'); this program reads version " +
                   std::to_string(kCheckpointVersion);
        return "";
    }
    if (const auto p = j.find("provenance"); p != j.end()) {
        if (j.size() != 1) return "a provenance record with other fields: " + names(j);
        if (!p->is_object()) return "provenance must be an object, got " + kind(*p);
        return "";
    }
    const auto k = j.find("key"), r = j.find("row");
    if (k != j.end() || r != j.end()) {
        if (k == j.end()) return "a point without its 'key' field";
        if (r == j.end()) return "a point without its 'row' field";
        if (!k->is_object()) return "key must be an object, got " + kind(*k);
        if (!r->is_object()) return "row must be an object, got " + kind(*r);
        if (j.size() != 2) return "a point with other fields: " + names(j);
        key = k->dump();
        return "";
    }
    return "neither a point {\"key\": {...}, \"row\": {...}} nor a provenance record {\"provenance\": {...}}: "
           "fields " +
           names(j);
}

/// The header line, as both programs write it.
std::string header_line() {
    return json({{"format", "hovering-checkpoint"}, {"version", kCheckpointVersion}}).dump();
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
        // Without a complete line, only a piece of the header can be a torn write (a run writes
        // its header, provenance and first point at once): anything else is another program's
        // file of one line without its newline, which must not be cut to nothing.
        const std::string head = header_line();
        if (offset_ == 0 && (line.size() >= head.size() || head.compare(0, line.size(), line) != 0))
            throw std::invalid_argument(path_ + " line 1: the first line is not the header " + head +
                                        ": another program's file (one line of " + std::to_string(line.size()) +
                                        " bytes without its newline); use another --out, or move the file away");
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
    if (lines_ == 0) text += header_line() + "\n";
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
