#pragma once
// Running a plan's points and keeping them in a checkpoint: the sweep executable's work, with the
// format and rules hovering.parallel.checkpoint implements for Python (docs/sweep-plan.md), so that
// either program resumes what the other began.
//
// A point is measured by the core's hovering_area (the samples, outcomes and estimate Python's
// hovering.hovering_area calls too) on the maps built from the point's numbers; a flow point also
// measures its truncated models on the same box. Its row holds the estimate's fields, the carried
// theory (and b1), the models' areas and the seconds it took.
//
// The checkpoint is JSON lines: a header {"format": "hovering-checkpoint", "version": 1}, then
// provenance lines {"provenance": {...}} (what wrote the points after it) and one line
// {"key": {...}, "row": {...}} per finished point. Keys are compared as parsed values. Every
// line is appended under an exclusive flock and fsync'd before the next point starts; a line
// another run appended meanwhile is read first, and a point it finished is neither computed nor
// written again. A last line without its newline (a run killed mid-write) is cut off and its point
// recomputed; any other line that is not one of these records, or a file whose first line is not
// this header, is refused untouched.

#include <atomic>
#include <cstdint>
#include <set>
#include <string>

#include "hovering/sweep/plan.hpp"

namespace hovering::sweep {

/// A computed point.
struct PointRow {
    std::string row;                                      ///< the row as canonical JSON text
    bool interrupted = false;                             ///< cancelled before it finished: not a result
    double area = 0, error = 0, theory = 0, seconds = 0;  ///< for the run's log
};

/// Measure point i of the plan. n_threads: 0 = all cores; cancel (optional) stops it early (then
/// interrupted is set); progress (optional) counts map steps / flow returns (point_work in all).
PointRow run_point(const Plan& plan, std::size_t i, int n_threads = 0, const std::atomic<bool>* cancel = nullptr,
                   std::atomic<std::int64_t>* progress = nullptr);

/// The steps / returns run_point(plan, i) counts in its progress when it is not cancelled (the
/// grid rounds samples up, so this is a close estimate).
double point_work(const Plan& plan, std::size_t i);

/// Memory one sample of a point takes while it is measured (its start, its outcomes under F_0 and
/// F_eps, steps done, regions visited, membership), counted as Python's hovering.hovering_area does.
constexpr double kBytesPerSample = 64;

/// Half of this machine's physical memory: what a run may take (Python's hovering_area budget).
std::uintmax_t memory_budget();

/// Refuse, before anything is computed or written (std::invalid_argument naming the plan, the point
/// and its samples, and the largest count allowed), a point whose samples need more than `budget`
/// bytes: without it a run died on std::bad_alloc after creating its checkpoint.
void check_memory(const Plan& plan, std::uintmax_t budget = memory_budget());

/// The checkpoint format this program reads and writes.
constexpr int kCheckpointVersion = 1;

/// A checkpoint file, open for reading finished points and appending new ones.
class Checkpoint {
public:
    /// Open (creating) path and read it under an exclusive lock: the header is checked, a torn
    /// last line is cut off (torn() says so), and a damaged line or a foreign file is refused
    /// (std::invalid_argument naming the file and line; the file is left as it was). A file this
    /// process may only read is read (writing it then fails with the reason).
    explicit Checkpoint(const std::string& path);
    ~Checkpoint();
    Checkpoint(const Checkpoint&) = delete;
    Checkpoint& operator=(const Checkpoint&) = delete;

    /// Whether the point with this key (canonical JSON) is in the file, as of now (lines other runs
    /// appended since the last look are read first, under a shared lock).
    bool done(const std::string& key);
    /// Append a finished point (and, before its first point, this run's provenance line; before
    /// anything, the header of a new file) under an exclusive lock, durably (fsync). False, writing
    /// nothing, when another run wrote the point meanwhile. std::runtime_error when the write fails
    /// (a full disk: the partial line is cut back off, earlier lines are kept).
    bool append(const std::string& key, const std::string& row, const std::string& provenance);
    /// Finished points in the file.
    std::size_t size() const { return keys_.size(); }
    /// What was cut off on opening ("" if nothing).
    const std::string& torn() const { return torn_; }
    /// The file's path.
    const std::string& path() const { return path_; }

private:
    void scan(bool may_cut);
    void write_all(const std::string& text, const char* what);
    std::string path_;
    int fd_ = -1;
    int read_only_ = 0;          ///< errno of opening for writing when only reading was possible
    std::uintmax_t offset_ = 0;  ///< bytes of complete lines read so far
    long lines_ = 0;             ///< complete lines read so far
    bool provenance_written_ = false;
    std::set<std::string> keys_;  ///< canonical keys of the finished points
    std::string torn_;
};

}  // namespace hovering::sweep
