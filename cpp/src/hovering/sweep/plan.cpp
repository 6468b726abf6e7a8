// Reading a resolved sweep plan: see plan.hpp and docs/sweep-plan.md. Type and range checks only;
// what a value means is the core's business (its constructors run on every point here).
#include "hovering/sweep/plan.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include <toml++/toml.h>
#include <nlohmann/json.hpp>

#include "hovering/detail/common.hpp"
#include "hovering/flow/potential.hpp"
#include "hovering/flow/return_map.hpp"
#include "hovering/sweep/json_number.hpp"
#include "hovering/sweep/plan_build.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering::sweep {

namespace {

using json = nlohmann::json;

constexpr std::int64_t kMaxCount = std::int64_t(1) << 53;  // counts exact in a double
constexpr std::size_t kMaxPoints = 1000000;
constexpr std::size_t kMaxTable = 100000;  // entries of a model's table (its key stays a checkpoint line)
constexpr std::uintmax_t kMaxPlanBytes = std::uintmax_t(256) << 20;

using detail::fmt;  // the core's one formatter of a double in a message

/// A value as the message shows it (TOML's spelling; tables and arrays by their kind).
std::string show(const toml::node& n) {
    if (auto s = n.as_string()) {
        std::string v;
        for (const char ch : s->get().substr(0, 60)) {  // one clean line: no control character
            const unsigned char c = static_cast<unsigned char>(ch);
            v.push_back(c < 0x20 || c == 0x7f ? '?' : ch);
        }
        if (s->get().size() > 60) v = v.substr(0, 57) + "...";
        return "'" + v + "'";
    }
    if (auto i = n.as_integer()) return std::to_string(i->get());
    if (auto f = n.as_floating_point()) return fmt(f->get());
    if (auto b = n.as_boolean()) return b->get() ? "true" : "false";
    if (n.is_table()) return "a table";
    if (n.is_array()) return "an array of " + std::to_string(n.as_array()->size());
    return "a date or time";
}

/// The reader of one table: every key it takes is named in a message on error, and any key it
/// did not take is refused at the end (a typo in a hand-written plan is not silently ignored).
class Table {
public:
    Table(const toml::table& t, std::string where) : t_(t), where_(std::move(where)) {}

    [[noreturn]] void fail(const std::string& key, const std::string& what) const {
        throw std::invalid_argument(where_ + key + what);
    }
    const toml::node* get(const std::string& key, bool required, const std::string& allowed) {
        used_.insert(key);
        const toml::node* n = t_.get(key);
        if (!n && required) fail(key, " is missing (" + allowed + ")");
        return n;
    }
    [[noreturn]] void bad(const std::string& key, const toml::node& n, const std::string& allowed) const {
        fail(key, " = " + show(n) + ": allowed: " + allowed);
    }
    double real(const std::string& key, double lo, double hi, bool finite = true, bool lo_open = false,
                bool hi_open = false) {
        const std::string allowed = range(lo, hi, finite, lo_open, hi_open);
        const toml::node* n = get(key, true, allowed);
        double v;
        if (auto f = n->as_floating_point())
            v = f->get();
        else if (auto i = n->as_integer())
            v = double(i->get());
        else
            bad(key, *n, allowed);
        const bool ok = !std::isnan(v) && (!finite || std::isfinite(v)) && v >= lo && v <= hi &&
                        !(lo_open && v == lo) && !(hi_open && v == hi);
        if (!ok) bad(key, *n, allowed);
        return v;
    }
    /// A number that may be anything (NaN and infinities included): carried values.
    double any_real(const std::string& key, bool required) {
        const toml::node* n = get(key, required, "a number");
        if (!n) return std::numeric_limits<double>::quiet_NaN();
        if (auto f = n->as_floating_point()) return f->get();
        if (auto i = n->as_integer()) return double(i->get());
        bad(key, *n, "a number");
    }
    std::int64_t integer(const std::string& key, std::int64_t lo, std::int64_t hi) {
        const std::string allowed = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
        const toml::node* n = get(key, true, allowed);
        auto i = n->as_integer();
        if (!i || i->get() < lo || i->get() > hi) bad(key, *n, allowed);
        return i->get();
    }
    std::string string(const std::string& key, const std::vector<std::string>& choices, bool required = true) {
        std::string allowed = "a string";
        if (!choices.empty()) {
            allowed = "one of";
            for (const auto& c : choices) allowed += " '" + c + "'";
        }
        const toml::node* n = get(key, required, allowed);
        if (!n) return "";
        auto s = n->as_string();
        if (!s || s->get().size() > 4096 ||
            (!choices.empty() && std::find(choices.begin(), choices.end(), s->get()) == choices.end()))
            bad(key, *n, allowed + (choices.empty() ? " of at most 4096 bytes" : ""));
        return s->get();
    }
    const toml::table& table(const std::string& key) {
        const toml::node* n = get(key, true, "a table");
        if (!n->is_table()) bad(key, *n, "a table");
        return *n->as_table();
    }
    const toml::array* array(const std::string& key, bool required, std::size_t lo, std::size_t hi) {
        const std::string allowed = "an array of " + std::to_string(lo) + " to " + std::to_string(hi) + " entries";
        const toml::node* n = get(key, required, allowed);
        if (!n) return nullptr;
        auto a = n->as_array();
        if (!a || a->size() < lo || a->size() > hi) bad(key, *n, allowed);
        return a;
    }
    std::vector<double> reals(const std::string& key, std::size_t lo, std::size_t hi) {
        const toml::array& a = *array(key, true, lo, hi);
        std::vector<double> out;
        out.reserve(a.size());
        for (std::size_t i = 0; i < a.size(); ++i) {
            double v = 0;
            if (auto f = a[i].as_floating_point())
                v = f->get();
            else if (auto n = a[i].as_integer())
                v = double(n->get());
            else
                fail(key + "[" + std::to_string(i) + "]", " = " + show(a[i]) + ": allowed: a finite number");
            if (!std::isfinite(v))
                fail(key + "[" + std::to_string(i) + "]", " = " + fmt(v) + ": allowed: a finite number");
            out.push_back(v);
        }
        return out;
    }
    /// Refuse the keys nobody took.
    void done() const {
        for (const auto& [k, v] : t_) {
            const std::string key(k.str());
            if (!used_.count(key))
                fail(key, " is not a key of this table (a typo? see docs/sweep-plan.md for the keys of a plan)");
        }
    }
    const std::string& where() const { return where_; }

private:
    static std::string range(double lo, double hi, bool finite, bool lo_open, bool hi_open) {
        const bool any_lo = lo == -std::numeric_limits<double>::infinity(),
                   any_hi = hi == std::numeric_limits<double>::infinity();
        std::string s = finite ? "a finite number" : "a number";
        if (any_lo && any_hi) return s;
        if (any_lo) return s + (hi_open ? " < " : " <= ") + fmt(hi);
        if (any_hi) return s + (lo_open ? " > " : " >= ") + fmt(lo);
        return s + " in " + (lo_open ? "(" : "[") + fmt(lo) + ", " + fmt(hi) + (hi_open ? ")" : "]");
    }
    const toml::table& t_;
    std::string where_;
    std::set<std::string> used_;
};

constexpr double kInf = std::numeric_limits<double>::infinity();

MapParams read_map(Table& t) {
    MapParams m;
    m.eps = t.real("eps", -kInf, kInf);
    m.Omega0 = t.real("Omega0", -1e6, 1e6);
    m.theta_w = t.real("theta_w", 0, 3.141592653589793, true, true, true);
    m.tau0 = t.real("tau0", -kInf, kInf);
    m.tau1 = t.real("tau1", -kInf, kInf);
    m.lam = t.real("lam", -kInf, kInf);
    t.done();
    return m;
}

PotentialSpec read_potential(Table& t) {
    // The core's registry of compiled potentials: its kinds, and each kind's parameters and ranges.
    std::vector<std::string> kinds;
    for (const PotentialKind& k : potential_kinds()) kinds.push_back(k.kind);
    PotentialSpec p;
    p.kind = t.string("kind", kinds);
    for (const PotentialParam& q : potential_kind(p.kind).params) p.params.push_back(t.real(q.name, q.lo, q.hi));
    t.done();
    return p;
}

SystemSpec read_system(Table& t) {
    SystemSpec s;
    {
        Table v(t.table("V1"), t.where() + "V1.");
        s.V1 = read_potential(v);
    }
    {
        Table v(t.table("V2"), t.where() + "V2.");
        s.V2 = read_potential(v);
    }
    const toml::array& c = *t.array("coupling", true, 0, 441);
    std::set<std::pair<int, int>> seen;
    for (std::size_t k = 0; k < c.size(); ++k) {
        const std::string at = "coupling[" + std::to_string(k) + "]";
        const std::string allowed =
            "a term [c, i, j]: c a finite number, i and j integers in [0, 20], each (i, j) once";
        auto a = c[k].as_array();
        if (!a || a->size() != 3) t.bad(at, c[k], allowed);
        const auto* cf = (*a)[0].as_floating_point();
        const auto* ci = (*a)[0].as_integer();
        const auto* i = (*a)[1].as_integer();
        const auto* j = (*a)[2].as_integer();
        if ((!cf && !ci) || !i || !j || i->get() < 0 || i->get() > 20 || j->get() < 0 || j->get() > 20)
            t.bad(at, c[k], allowed);
        CouplingTerm term{cf ? cf->get() : double(ci->get()), int(i->get()), int(j->get())};
        if (!std::isfinite(term.c) || !seen.insert({term.i, term.j}).second) t.bad(at, c[k], allowed);
        s.coupling.push_back(term);
    }
    s.eps = t.real("eps", -kInf, kInf);
    s.qw1 = t.real("qw1", -kInf, 0, true, false, true);
    s.qw2 = t.real("qw2", -kInf, 0, true, false, true);
    s.geometry = t.string("geometry", {"none", "wall", "step"});
    t.done();
    return s;
}

IntegratorSpec read_integrator(Table& t) {
    IntegratorSpec it;
    // The choices are the core's list: the name is checked here (the message names the key) and
    // parsed once into the core's enum.
    it.stepper = parse_stepper(t.string("stepper", std::vector<std::string>(kSteppers.begin(), kSteppers.end())));
    it.rtol = t.real("rtol", 0, 1, true, true, true);
    it.atol = t.real("atol", 0, kInf, true, true);
    // The core's ranges (FlowOptions::validate), each key named here.
    it.event_tol = t.real("event_tol", 0, kInf, true, true);
    it.max_steps = t.integer("max_steps", 1, std::numeric_limits<std::int64_t>::max());
    it.max_impacts = int(t.integer("max_impacts", 1, 1000000));
    it.grazing_tol = t.real("grazing_tol", 0, kInf);
    it.corner_tol = t.real("corner_tol", 0, kInf);
    it.verify_steps = t.integer("verify_steps", -1, std::numeric_limits<std::int64_t>::max());
    t.done();
    return it;
}

ModelSpec read_model(Table& t) {
    ModelSpec m;
    m.name = t.string("name", {});
    m.K_low = t.real("K_low", -kInf, 0, true, false, true);
    m.eps = t.real("eps", -kInf, kInf);
    m.K = t.reals("K", 4, kMaxTable);
    for (const char* name : {"Omega", "JR", "J1"}) {
        std::vector<double> v = t.reals(name, m.K.size(), m.K.size());
        (std::string(name) == "Omega" ? m.Omega : std::string(name) == "JR" ? m.JR : m.J1) = std::move(v);
    }
    m.forcing = t.reals("forcing", 1, 64);
    m.K_max = t.real("K_max", -kInf, kInf, false);
    t.done();
    return m;
}

// ------------------------------------------------------------------ the key


json jreals(const std::vector<double>& v) {
    json a = json::array();
    for (double x : v) a.push_back(jnum(x));
    return a;
}

json potential_key(const PotentialSpec& p) {
    json j = {{"kind", p.kind}};
    const std::vector<PotentialParam>& names = potential_kind(p.kind).params;
    for (std::size_t i = 0; i < names.size(); ++i) j[names[i].name] = jnum(p.params[i]);
    return j;
}

std::string point_key(const std::string& kind, const PlanPoint& p) {
    json k = {
        {"kind", kind}, {"n_steps", p.n_steps}, {"samples", p.samples}, {"seed", p.seed}, {"K_low", jnum(p.K_low)}};
    if (kind == "hovering_area") {
        const MapParams& m = p.map;
        k["map"] = {{"eps", jnum(m.eps)},   {"Omega0", jnum(m.Omega0)}, {"theta_w", jnum(m.theta_w)},
                    {"tau0", jnum(m.tau0)}, {"tau1", jnum(m.tau1)},     {"lam", jnum(m.lam)}};
    } else {
        const SystemSpec& s = p.system;
        json coupling = json::array();
        for (const auto& t : s.coupling) coupling.push_back(json::array({jnum(t.c), t.i, t.j}));
        k["system"] = {{"V1", potential_key(s.V1)}, {"V2", potential_key(s.V2)}, {"coupling", coupling},
                       {"eps", jnum(s.eps)},        {"qw1", jnum(s.qw1)},        {"qw2", jnum(s.qw2)},
                       {"geometry", s.geometry}};
        k["h"] = jnum(p.h);
        const IntegratorSpec& it = p.integrator;
        k["integrator"] = {{"stepper", stepper_name(it.stepper)}, {"rtol", jnum(it.rtol)},
                           {"atol", jnum(it.atol)},           {"event_tol", jnum(it.event_tol)},
                           {"max_steps", it.max_steps},       {"max_impacts", it.max_impacts},
                           {"grazing_tol", jnum(it.grazing_tol)}, {"corner_tol", jnum(it.corner_tol)},
                           {"verify_steps", it.verify_steps}};
        json models = json::array();
        for (const auto& m : p.models)
            models.push_back({{"name", m.name},
                              {"K_low", jnum(m.K_low)},
                              {"eps", jnum(m.eps)},
                              {"K", jreals(m.K)},
                              {"Omega", jreals(m.Omega)},
                              {"JR", jreals(m.JR)},
                              {"J1", jreals(m.J1)},
                              {"forcing", jreals(m.forcing)},
                              {"K_max", jnum(m.K_max)}});
        k["models"] = models;
    }
    return k.dump();
}

PlanPoint read_point(Table& t, const std::string& kind) {
    PlanPoint p;
    p.label = t.string("label", {}, false);
    p.n_steps = t.integer("n_steps", 4, kMaxCount);
    p.samples = t.integer("samples", 1, kMaxCount);
    p.seed = std::uint64_t(t.integer("seed", 0, std::numeric_limits<std::int64_t>::max()));
    p.K_low = t.real("K_low", -kInf, 0, true, false, true);
    p.theory = t.any_real("theory", false);
    if (kind == "hovering_area") {
        Table m(t.table("map"), t.where() + "map.");
        p.map = read_map(m);
    } else {
        p.b1 = t.any_real("b1", false);
        Table s(t.table("system"), t.where() + "system.");
        p.system = read_system(s);
        p.h = t.real("h", -kInf, kInf);
        Table it(t.table("integrator"), t.where() + "integrator.");
        p.integrator = read_integrator(it);
        if (const toml::array* models = t.array("models", false, 0, 16)) {
            std::set<std::string> names;
            for (std::size_t i = 0; i < models->size(); ++i) {
                const std::string at = "models[" + std::to_string(i) + "]";
                if (!(*models)[i].is_table()) t.bad(at, (*models)[i], "a table");
                Table m(*(*models)[i].as_table(), t.where() + at + ".");
                p.models.push_back(read_model(m));
                if (!names.insert(p.models.back().name).second)
                    t.fail(at + ".name",
                           " = '" + p.models.back().name + "': allowed: a name no other model of the point has");
            }
        }
    }
    t.done();
    p.key = point_key(kind, p);
    return p;
}

/// Most parts of one dotted key or table header (`a.b.c = 1`, `[a.b.c]`): a plan's have at most 3,
/// and the TOML reader builds one nested table per part, recursively (100,000 parts crashed it).
constexpr std::size_t kMaxKeyParts = 16;

/// Refuse (std::invalid_argument naming the line) a dotted key of more than kMaxKeyParts parts,
/// before the TOML reader sees the text. A linear scan that skips strings and comments and counts
/// the dots of each stretch between `= , [ ] { }` and line ends (a number or a date has at most one).
void check_key_parts(const std::string& text, const std::string& where) {
    std::size_t line = 1, dots = 0;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (c == '#') {
            while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
        } else if (c == '"' || c == '\'') {
            const bool multi = text.compare(i, 3, std::string(3, c)) == 0;
            i += multi ? 3 : 1;
            for (; i < text.size(); ++i) {
                if (text[i] == '\n') {
                    ++line;
                    if (!multi) break;  // an unterminated string: the TOML reader says so
                } else if (c == '"' && text[i] == '\\') {
                    if (i + 1 < text.size() && text[i + 1] == '\n') ++line;
                    ++i;
                } else if (text[i] == c && (!multi || text.compare(i, 3, std::string(3, c)) == 0)) {
                    if (multi) {
                        i += 2;
                        while (i + 1 < text.size() && text[i + 1] == c) ++i;  // """" ends with a quote
                    }
                    break;
                }
            }
        } else if (c == '.') {
            if (++dots >= kMaxKeyParts)
                throw std::invalid_argument(where + " line " + std::to_string(line) + ": a dotted key of more than " +
                                            std::to_string(kMaxKeyParts) + " parts: allowed: at most " +
                                            std::to_string(kMaxKeyParts) + " (a plan's keys have at most 3)");
        } else if (c == '\n' || c == '=' || c == ',' || c == '[' || c == ']' || c == '{' || c == '}') {
            dots = 0;
            line += c == '\n';
        }
    }
}

}  // namespace

std::string format_number(double x) {
    return detail::fmt(x);
}

Plan parse_plan(const std::string& text, const std::string& where) {
    check_key_parts(text, where);
    toml::table root;
    try {
        root = toml::parse(text, where);
    } catch (const toml::parse_error& e) {
        const auto& b = e.source().begin;
        throw std::invalid_argument(where + " line " + std::to_string(b.line) +
                                    ": not a TOML file: " + std::string(e.description()));
    }
    Plan plan;
    Table t(root, where + ": ");
    const std::string format = t.string("format", {"hovering-sweep-plan"});
    (void)format;
    const toml::node* v = t.get("version", true, "an integer");
    if (!v->as_integer() || v->as_integer()->get() != kPlanVersion)
        t.fail("version", " = " + show(*v) + ": this hovering_sweep reads plan version " +
                              std::to_string(kPlanVersion) +
                              " (write the plan again with this version's python -m hovering plan)");
    plan.kind = t.string("kind", {"hovering_area", "flow_hovering_area"});
    plan.name = t.string("name", {}, false);
    plan.checkpoint = t.string("checkpoint", {}, false);
    const toml::array& points = *t.array("points", true, 1, kMaxPoints);
    std::set<std::string> keys;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const std::string at = "points[" + std::to_string(i) + "]";
        if (!points[i].is_table()) t.bad(at, points[i], "a table");
        Table pt(*points[i].as_table(), where + ": " + at + ".");
        plan.points.push_back(read_point(pt, plan.kind));
        try {
            check_point(plan.kind, plan.points.back());
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(where + ": " + at + ": " + e.what());
        }
        if (!keys.insert(plan.points.back().key).second)
            throw std::invalid_argument(where + ": " + at +
                                        " has the parameters of an earlier point (each point once)");
    }
    t.done();
    return plan;
}

Plan load_plan(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw std::invalid_argument(path + " is not a regular file (a plan)");
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) throw std::invalid_argument("cannot read " + path + ": " + ec.message());
    if (size > kMaxPlanBytes)
        throw std::invalid_argument(path + " has " + std::to_string(size) + " bytes; allowed: at most " +
                                    std::to_string(kMaxPlanBytes) + " for a plan");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::invalid_argument("cannot read " + path);
    std::ostringstream ss;
    ss << in.rdbuf();
    Plan p = parse_plan(ss.str(), path);
    p.path = path;
    return p;
}

}  // namespace hovering::sweep
