// The sweep plan reader (type and range checks, version, exact numbers, keys) and the checkpoint
// file (header, torn and damaged lines, keys compared as values, no duplicates), the parts of
// hovering_sweep that are not the core's numerics.
#include <fcntl.h>
#include <unistd.h>

#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "hovering/flow/potential.hpp"
#include "hovering/sweep/plan.hpp"
#include "hovering/sweep/plan_build.hpp"
#include "hovering/sweep/run.hpp"
#include "testing.hpp"

using namespace hovering::sweep;
namespace fs = std::filesystem;

namespace {

const std::string kHead = "format = \"hovering-sweep-plan\"\nversion = 1\nkind = \"hovering_area\"\n";
const std::string kPoint =
    "[[points]]\nn_steps = 400\nsamples = 2000\nseed = 0\nK_low = -0.2145848093800635\ntheory = 0.1\n"
    "map = { eps = 0.1, Omega0 = 3.883222077450933, theta_w = 2.356194490192345, tau0 = 1.0, tau1 = 0.5, lam = 0.5 }\n";

/// kPoint with one line replaced (the line starting with `key =`), or a line added.
std::string point_with(const std::string& key, const std::string& line) {
    std::istringstream in(kPoint);
    std::string out, l;
    bool done = false;
    while (std::getline(in, l)) {
        if (!done && l.compare(0, key.size() + 3, key + " = ") == 0) {
            if (!line.empty()) out += line + "\n";
            done = true;
        } else {
            out += l + "\n";
        }
    }
    if (!done) out += line + "\n";
    return out;
}

const std::string kFlow = R"(format = "hovering-sweep-plan"
version = 1
kind = "flow_hovering_area"
[[points]]
n_steps = 50
samples = 100
seed = 0
K_low = -0.1
theory = 0.2
b1 = 0.5
h = 1.0
system = { V1 = { kind = "harmonic", omega = 1.0 }, V2 = { kind = "tan", omega = 1.4, alpha = 0.7 }, coupling = [[1.0, 1, 1]], eps = -0.1, qw1 = -1.0, qw2 = -0.5, geometry = "step" }
integrator = { stepper = "rk8pd", rtol = 1e-10, atol = 1e-10, event_tol = 1e-15, max_steps = 1000000, max_impacts = 100, grazing_tol = 1e-12, corner_tol = 1e-10, verify_steps = -1 }
)";

std::string tmp(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("hovering_test_plan_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return (d / name).string();
}

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void spit(const std::string& path, const std::string& text) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

}  // namespace

TEST_CASE("a hand-written plan is read with its numbers exact and its key canonical", "[plan]") {
    const Plan p = parse_plan(kHead + kPoint, "p.toml");
    REQUIRE(p.points.size() == 1);
    const PlanPoint& q = p.points[0];
    CHECK(p.kind == "hovering_area");
    CHECK(q.n_steps == 400);
    CHECK(q.K_low == -0.2145848093800635);
    CHECK(q.map.Omega0 == 3.883222077450933);
    CHECK(q.theory == 0.1);
    // Sorted keys, shortest round-trip numbers, the kind; label and theory are not parameters.
    CHECK(q.key ==
          "{\"K_low\":-0.2145848093800635,\"kind\":\"hovering_area\",\"map\":{\"Omega0\":3.883222077450933,\"eps\":0.1,"
          "\"lam\":0.5,\"tau0\":1.0,\"tau1\":0.5,\"theta_w\":2.356194490192345},\"n_steps\":400,\"samples\":2000,"
          "\"seed\":0}");
    const Plan labelled = parse_plan(kHead + point_with("theory", "theory = 0.7\nlabel = \"x\""), "p.toml");
    CHECK(labelled.points[0].key == q.key);
    // An integer where a number is asked is that number (a person may write tau0 = 1).
    CHECK(parse_plan(kHead + point_with("map",
                                        "map = { eps = 0.1, Omega0 = 3.883222077450933, theta_w = "
                                        "2.356194490192345, tau0 = 1, tau1 = 0.5, lam = 0.5 }"),
                     "p.toml")
              .points[0]
              .key == q.key);
}

TEST_CASE("every double a plan holds reads back bit for bit", "[plan]") {
    // Python writes repr(float), the shortest text that reads back as that double; the reader must
    // give the same double, or the two programs would sample other boxes. Doubles over the whole
    // range, printed the same way (std::to_chars shortest), read by the plan reader.
    std::mt19937_64 rng(7);
    std::string text = kHead;
    std::vector<double> xs;
    for (int i = 0; i < 2000; ++i) {
        double x;
        do {
            std::uint64_t bits = rng();
            std::memcpy(&x, &bits, sizeof x);
        } while (!std::isfinite(x));
        xs.push_back(x);
    }
    for (std::size_t i = 0; i < xs.size(); ++i) {
        char buf[64];
        const auto r = std::to_chars(buf, buf + sizeof buf, xs[i]);
        std::string s(buf, r.ptr);
        if (s.find_first_of(".eE") == std::string::npos) s += ".0";  // TOML floats need a dot or exponent
        text += "[[points]]\nn_steps = 400\nsamples = 2000\nseed = " + std::to_string(i) +
                "\nK_low = -0.1\ntheory = " + s +
                "\nmap = { eps = 0.1, Omega0 = 3.9, theta_w = 2.3, tau0 = 1.0, tau1 = 0.5, lam = 0.5 }\n";
    }
    const Plan p = parse_plan(text, "p.toml");
    REQUIRE(p.points.size() == xs.size());
    for (std::size_t i = 0; i < xs.size(); ++i) REQUIRE(std::memcmp(&p.points[i].theory, &xs[i], sizeof(double)) == 0);
}

TEST_CASE("bad plans: one message naming the file, the key, the value and what is allowed", "[plan]") {
    const auto bad = [](const std::string& text, const std::string& needle) {
        INFO(text);
        CHECK_INVALID(parse_plan(text, "p.toml"), needle);
    };
    bad(kHead + point_with("n_steps", "n_steps = 2"),
        "p.toml: points[0].n_steps = 2: allowed: an integer in [4, 9007199254740992]");
    bad(kHead + point_with("samples", "samples = \"many\""), "points[0].samples = 'many': allowed: an integer");
    bad(kHead + point_with("seed", "seed = -1"),
        "points[0].seed = -1: allowed: an integer in [0, 9223372036854775807]");
    bad(kHead + point_with("K_low", "K_low = 0.5"), "points[0].K_low = 0.5: allowed: a finite number < 0");
    bad(kHead + point_with("K_low", "K_low = nan"), "points[0].K_low = nan");
    bad(kHead + point_with("K_low", ""), "points[0].K_low is missing (a finite number < 0)");
    bad(kHead +
            point_with("map", "map = { eps = 0.1, Omega0 = 3.9, theta_w = 4.0, tau0 = 1.0, tau1 = 0.5, lam = 0.5 }"),
        "points[0].map.theta_w = 4: allowed: a finite number in (0, 3.141592653589793)");
    bad(kHead + point_with("map", "map = { eps = 0.1, Omega0 = 3.9, theta_w = 2.0, tau0 = 1.0, tau1 = 0.5 }"),
        "points[0].map.lam is missing");
    bad(kHead + point_with("seed", "seed = 0\nsed = 1"), "points[0].sed is not a key of this table");
    bad(kHead + kPoint + kPoint, "p.toml: points[1] has the parameters of an earlier point");
    // The core refuses what the reader let through: named with the point.
    bad(kHead + point_with("K_low", "K_low = -50.0"), "p.toml: points[0]: K_low = ");
    bad("format = \"hovering-sweep-plan\"\nversion = 2\nkind = \"hovering_area\"\n" + kPoint,
        "p.toml: version = 2: this hovering_sweep reads plan version 1");
    bad("format = \"a-scene\"\nversion = 1\nkind = \"hovering_area\"\n" + kPoint,
        "p.toml: format = 'a-scene': allowed: one of 'hovering-sweep-plan'");
    bad("format = \"hovering-sweep-plan\"\nversion = 1\nkind = \"portrait\"\n" + kPoint,
        "kind = 'portrait': allowed: one of 'hovering_area' 'flow_hovering_area'");
    bad(kHead, "p.toml: points is missing");
    bad(kHead + "points = []\n", "p.toml: points = an array of 0: allowed: an array of 1 to");
    bad("kind = [\n", "p.toml line ");
    // Flow points: system, integrator and models.
    const auto flow = [&](const std::string& from, const std::string& to, const std::string& needle) {
        std::string t = kFlow;
        const auto at = t.find(from);
        REQUIRE(at != std::string::npos);
        bad(t.replace(at, from.size(), to), needle);
    };
    CHECK(parse_plan(kFlow, "f.toml").points[0].system.coupling.size() == 1);
    flow("stepper = \"rk8pd\"", "stepper = \"euler\"",
         "points[0].integrator.stepper = 'euler': allowed: one of 'auto' 'rk8pd'");
    flow("rtol = 1e-10", "rtol = 2.0", "points[0].integrator.rtol = 2: allowed: a finite number in (0, 1)");
    // The other FlowOptions fields: each explicit, in the core's range, named with its key.
    flow("verify_steps = -1", "verify_steps = -2", "points[0].integrator.verify_steps = -2: allowed: an integer in [-1, ");
    flow("max_impacts = 100", "max_impacts = 0", "points[0].integrator.max_impacts = 0: allowed: an integer in [1, 1000000]");
    flow("max_steps = 1000000", "max_steps = 1.5", "points[0].integrator.max_steps = 1.5: allowed: an integer in [1, ");
    flow("event_tol = 1e-15", "event_tol = 0.0", "points[0].integrator.event_tol = 0");
    flow("grazing_tol = 1e-12", "grazing_tol = -1e-12", "points[0].integrator.grazing_tol = -1e-12");
    flow(", verify_steps = -1", "", "points[0].integrator.verify_steps is missing");
    {
        // They reach the flow's options and the checkpoint key (a point with other options is
        // another point).
        std::string t = kFlow;
        const auto at = t.find("verify_steps = -1");
        REQUIRE(at != std::string::npos);
        const Plan a = parse_plan(kFlow, "f.toml");
        const Plan b = parse_plan(t.replace(at, 17, "verify_steps = 0"), "f.toml");
        CHECK(a.points[0].integrator.verify_steps == -1);
        CHECK(b.points[0].integrator.verify_steps == 0);
        CHECK(a.points[0].integrator.max_impacts == 100);
        CHECK(a.points[0].integrator.event_tol == 1e-15);
        CHECK(a.points[0].key != b.points[0].key);
        CHECK(b.points[0].key.find("\"verify_steps\":0") != std::string::npos);
        // Each field reaches the core's options as written (none left at its default).
        std::string u = kFlow;
        const auto line = u.find("integrator = {");
        REQUIRE(line != std::string::npos);
        u.replace(line, u.find('\n', line) - line,
                  "integrator = { stepper = \"rk8pd\", rtol = 1e-9, atol = 1e-8, event_tol = 1e-13, max_steps = 5000, "
                  "max_impacts = 7, grazing_tol = 1e-11, corner_tol = 1e-6, verify_steps = 9 }");
        const Plan cp = parse_plan(u, "f.toml");
        const PlanPoint& c = cp.points[0];
        const hovering::FlowOptions o = build_options(c.integrator, build_system(c.system, c.system.eps));
        CHECK((o.stepper == hovering::Stepper::Rk8pd && o.rtol == 1e-9 && o.atol == 1e-8));
        CHECK((o.event_tol == 1e-13 && o.max_steps == 5000 && o.max_impacts == 7));
        CHECK((o.grazing_tol == 1e-11 && o.corner_tol == 1e-6 && o.verify_steps == 9));
    }
    flow("coupling = [[1.0, 1, 1]]", "coupling = [[1.0, 1, 21]]", "points[0].system.coupling[0] = an array of 3");
    flow("coupling = [[1.0, 1, 1]]", "coupling = [[1.0, 1, 1], [2.0, 1, 1]]", "each (i, j) once");
    flow("kind = \"tan\", omega = 1.4, alpha = 0.7", "kind = \"tan\", omega = 1.4",
         "points[0].system.V2.alpha is missing");
    // The kinds and their parameters' ranges are the core's registry (potential_kinds()).
    std::string kinds;
    for (const hovering::PotentialKind& k : hovering::potential_kinds()) kinds += " '" + k.kind + "'";
    flow("kind = \"tan\", omega = 1.4, alpha = 0.7", "kind = \"cubic\", omega = 1.4, alpha = 0.7",
         "points[0].system.V2.kind = 'cubic': allowed: one of" + kinds);
    flow("kind = \"tan\", omega = 1.4, alpha = 0.7", "kind = \"tan\", omega = 1e200, alpha = 0.7",
         "points[0].system.V2.omega = 1e+200: allowed:");
    flow("kind = \"tan\", omega = 1.4, alpha = 0.7", "kind = \"harmonic\", omega = 1.4, alpha = 0.7",
         "points[0].system.V2.alpha is not a key of this table");
    flow("qw2 = -0.5", "qw2 = 0.5", "points[0].system.qw2 = 0.5: allowed: a finite number < 0");
    flow("geometry = \"step\"", "geometry = \"box\"", "geometry = 'box': allowed: one of 'none' 'wall' 'step'");
    flow("integrator = { stepper = \"rk8pd\", rtol = 1e-10, atol = 1e-10, event_tol = 1e-15, max_steps = 1000000, max_impacts = 100, grazing_tol = 1e-12, corner_tol = 1e-10, verify_steps = -1 }\n",
         "integrator = { stepper = \"rk8pd\", rtol = 1e-10, atol = 1e-10, event_tol = 1e-15, max_steps = 1000000, max_impacts = 100, grazing_tol = 1e-12, corner_tol = 1e-10, verify_steps = -1 }\n[[points.models]]\nname = \"m\"\nK_low = "
         "-0.1\n"
         "eps = 0.1\nK = [-1.0, -0.5, 0.0, 0.5]\nOmega = [1.0, 1.0, 1.0]\nJR = [1.0, 1.0, 1.0, 0.0]\n"
         "J1 = [1.0, 0.5, 0.0, 0.0]\nforcing = [1.0]\nK_max = inf\n",
         "points[0].models[0].Omega = an array of 3: allowed: an array of 4 to 4 entries");
}

TEST_CASE("crafted plans: refused with one bounded message, never a crash; sizes checked before a run", "[plan]") {
    // Before: a dotted key of 100,000 parts crashed the TOML reader (one nested table per part,
    // built recursively); now refused by a linear scan before it runs.
    std::string deep = "x";
    for (int i = 0; i < 100000; ++i) deep += ".a";
    CHECK_INVALID(parse_plan(kHead + deep + " = 1\n" + kPoint, "p.toml"),
                  "p.toml line 4: a dotted key of more than 16 parts: allowed: at most 16");
    CHECK_INVALID(parse_plan(kHead + "[" + deep + "]\n", "p.toml"), "p.toml line 4: a dotted key of more than 16");
    // Dots in strings, comments, numbers and a plan's own dotted keys are no key parts.
    const std::string dots(40, '.');
    const Plan ok =
        parse_plan(kHead + "name = \"" + dots + "\" # " + dots + "\ncheckpoint = '''" + dots + "\n" + dots + "'''\n" +
                       point_with("map",
                                  "map.eps = 0.1\nmap.Omega0 = 3.883222077450933\nmap.theta_w = "
                                  "2.356194490192345\nmap.tau0 = 1.0\nmap.tau1 = 0.5\nmap.lam = 0.5"),
                   "p.toml");
    CHECK(ok.name == dots);
    // A message shows numbers as they read back (before: "-0.000000", or 300 digits for 1e300).
    CHECK_INVALID(parse_plan(kHead + point_with("K_low", "K_low = -1e300"), "p.toml"),
                  "p.toml: points[0]: K_low = -1e+300 lies below the map's band (lower end -3.14159");
    // Samples beyond the memory budget: refused before anything is computed or written (before: a
    // std::bad_alloc once the run had started).
    const Plan huge = parse_plan(kHead + point_with("samples", "samples = 9007199254740992"), "p.toml");
    CHECK_INVALID(check_memory(huge, std::uintmax_t(1) << 30),
                  "plan: points[0].samples = 9007199254740992 needs 5.37e+08 GiB, more than 1 GiB (half of this "
                  "machine's memory): allowed: at most 16777216 samples here");
    CHECK_NOTHROW(check_memory(huge, std::uintmax_t(1) << 62));
    CHECK_NOTHROW(check_memory(parse_plan(kHead + kPoint, "p.toml")));
}

TEST_CASE("checkpoint: header, points by key, torn and damaged lines", "[checkpoint]") {
    const std::string path = tmp("c.jsonl");
    fs::remove(path);
    const std::string key = "{\"kind\":\"hovering_area\",\"n_steps\":400,\"x\":0.1}";
    {
        Checkpoint c(path);
        CHECK(c.size() == 0);
        CHECK(!c.done(key));
        CHECK(c.append(key, "{\"area\":1.5}", "{\"program\":\"test\"}"));
        CHECK(c.done(key));
        CHECK(!c.append(key, "{\"area\":2.5}", "{\"program\":\"test\"}"));  // never twice
    }
    CHECK(slurp(path) ==
          "{\"format\":\"hovering-checkpoint\",\"version\":1}\n{\"provenance\":{\"program\":\"test\"}}\n" +
              std::string("{\"key\":") + key + ",\"row\":{\"area\":1.5}}\n");
    // Keys are compared as values: another program's spacing, key order and number spelling match.
    spit(path, slurp(path) + "{\"row\": {}, \"key\": {\"x\": 1.0e-1, \"n_steps\": 4e2, \"kind\": \"b\"}}\n");
    {
        Checkpoint c(path);
        CHECK(c.size() == 2);
        CHECK(c.done("{\"kind\":\"b\",\"n_steps\":400.0,\"x\":0.1}"));
    }
    // A last line without its newline (a run killed mid-write) is cut off.
    const std::string good = slurp(path);
    spit(path, good + "{\"key\":{\"x\":0.2},\"ro");
    {
        Checkpoint c(path);
        CHECK(!c.torn().empty());
        CHECK(c.size() == 2);
    }
    CHECK(slurp(path) == good);
    // A damaged line with lines after it, or any complete line that is not a record: refused, untouched.
    for (const std::string& broken :
         {std::string("{\"key\":{\"x\":0.2},\"ro\n"), std::string("[1, 2]\n"),
          std::string("{\"key\":{\"x\":NaN},\"row\":{}}\n"), std::string("{\"key\":{},\"row\":{},\"extra\":1}\n")}) {
        const std::string text = good + broken + "{\"key\":{\"x\":0.3},\"row\":{}}\n";
        spit(path, text);
        CHECK_INVALID(Checkpoint{path}, "line 5: ");
        CHECK(slurp(path) == text);
    }
    // Another program's file, or another version of this one: refused, untouched.
    for (const std::string& first : {std::string("area,error\n"), std::string("{\"key\":{},\"row\":{}}\n"),
                                     std::string("{\"format\":\"hovering-checkpoint\",\"version\":2}\n")}) {
        spit(path, first);
        CHECK_INVALID(Checkpoint{path}, "line 1: ");
        CHECK(slurp(path) == first);
    }
    CHECK_INVALID(Checkpoint{fs::temp_directory_path().string()}, "is not a regular file");
    fs::remove_all(fs::path(path).parent_path());
}

TEST_CASE("checkpoint: crafted lines are refused naming the file, the line and the field, never a crash",
          "[checkpoint]") {
    const std::string path = tmp("crafted.jsonl");
    const std::string head = "{\"format\":\"hovering-checkpoint\",\"version\":1}\n";
    const std::string good = head + "{\"key\":{\"a\":1},\"row\":{}}\n";
    const auto deep = [](std::size_t n, const std::string& open, const std::string& close) {
        std::string s;
        for (std::size_t i = 0; i < n; ++i) s += open;
        s += "1";
        for (std::size_t i = 0; i < n; ++i) s += close;
        return s;
    };
    struct Case {
        std::string line, needle;
    };
    // Before: the deep keys crashed (dumping them recursed once per level: a stack overflow); 1e999
    // and NaN said "not a line of JSON" and nothing of where; a huge integer was read as another
    // number; a name twice kept its last value; a byte-order mark was skipped.
    const std::vector<Case> cases = {
        {"{\"key\":" + deep(200000, "{\"a\":", "}") + ",\"row\":{}}",
         "line 3: not a line of JSON: nested deeper than 100 levels, in key.a.a.a"},
        {"{\"key\":{\"b\":" + deep(1000000, "[", "]") + "},\"row\":{}}",
         "line 3: not a line of JSON: nested deeper than 100 levels, in key.b[0][0]"},
        {"{\"key\":{},\"row\":" + deep(100000, "{\"r\":", "}") + "}", "nested deeper than 100 levels, in row.r.r"},
        {"{\"provenance\":" + deep(100000, "[", "]") + "}", "nested deeper than 100 levels, in provenance[0]"},
        {"{\"key\":" + std::string(3000000, '['), "nested deeper than 100 levels, in key[0][0]"},
        {"{\"key\":{\"x\":1e999},\"row\":{}}", "line 3: not a line of JSON: number overflow parsing '1e999'"},
        {"{\"key\":{\"x\":1},\"row\":{\"area\":-1e999}}", "number overflow parsing '-1e999' at byte 35, in row.area"},
        {"{\"key\":{\"n\":123456789012345678901234567890},\"row\":{}}",
         "line 3: key.n: the integer 123456789012345678901234567890 is beyond 64 bits"},
        {"{\"key\":{\"n\":-9223372036854775809},\"row\":{}}",
         "line 3: key.n: the integer -9223372036854775809 is beyond"},
        {"{\"key\":{\"x\":NaN},\"row\":{}}", "line 3: not a line of JSON: invalid literal at byte 13, in key.x"},
        {"{\"key\":{\"x\":\"\xff\xfe\"},\"row\":{}}", "line 3: not a line of JSON: invalid string: ill-formed UTF-8"},
        {"{\"key\":{\"s\":\"\\ud800\"},\"row\":{}}",
         "invalid string: surrogate U+D800..U+DBFF must be followed by U+DC00..U+DFFF at byte 20, in key.s"},
        {"{\"key\":{\"a\":[1,2,\"x\x01\"]},\"row\":{}}",
         "invalid string: control character U+0001 (SOH) must be escaped to \\u0001 at byte 20, in key.a[2]"},
        {"{\"key\":{\"x\":1},\"key\":{\"x\":2},\"row\":{}}", "line 3: key: the name 'key' twice in one object"},
        {"{\"key\":{\"m\":{\"a\":1,\"a\":2}},\"row\":{}}", "line 3: key.m.a: the name 'a' twice in one object"},
        {"{\"key\":{\"eps\":0.1,\"n\":},\"row\":{}}",
         "line 3: not a line of JSON: unexpected '}'; expected '[', '{', or a literal at byte 23, in key.n"},
        {"{\"key\":1,\"row\":{}}", "line 3: key must be an object, got a number 1"},
        {"{\"key\":{},\"row\":\"" + std::string(100000, 'x') + "\"}",
         "line 3: row must be an object, got a string \"xxx"},
        {"{\"key\":{}}", "line 3: a point without its 'row' field"},
        {"{\"row\":{}}", "line 3: a point without its 'key' field"},
        {"{\"key\":{},\"row\":{},\"extra\":1}", "line 3: a point with other fields: 'extra', 'key', 'row'"},
        {"{\"provenance\":[1]}", "line 3: provenance must be an object, got an array"},
        {"{\"other\":1}", "line 3: neither a point"},
        {"[1, 2]", "line 3: not a JSON object: the line is an array"},
        {"", "line 3: not a line of JSON: unexpected end of input"},
        {"\xEF\xBB\xBF{\"key\":{},\"row\":{}}", "line 3: not a line of JSON: a byte-order mark"},
    };
    for (const Case& c : cases) {
        const std::string text = good + c.line + "\n" + "{\"key\":{\"x\":0.3},\"row\":{}}\n";
        spit(path, text);
        INFO(c.line.substr(0, 60));
        CHECK_INVALID(Checkpoint{path}, path + " line 3: ");
        CHECK_INVALID(Checkpoint{path}, c.needle);
        try {
            Checkpoint{path};
        } catch (const std::invalid_argument& e) {
            CHECK(std::string(e.what()).size() < 600);  // one bounded line
        }
        CHECK(slurp(path) == text);
    }
    // The header: a bounded message naming 'version'.
    for (const auto& [first, needle] : std::vector<std::pair<std::string, std::string>>{
             {"{\"format\":\"hovering-checkpoint\",\"version\":" + deep(1000000, "[", "]") + "}",
              "line 1: the first line is not the header"},
             {"{\"format\":\"hovering-checkpoint\",\"version\":\"" + std::string(10000000, 'x') + "\"}",
              "line 1: a checkpoint of version \"xxx"},
             {"{\"format\":\"hovering-checkpoint\",\"version\":1e400}",
              "line 1: the first line is not the header {\"format\": \"hovering-checkpoint\", \"version\": 1}: another "
              "program's file (not a line of JSON: number overflow parsing '1e400' at byte 47, in version)"},
         }) {
        spit(path, first + "\n");
        CHECK_INVALID(Checkpoint{path}, path + " " + needle);
        try {
            Checkpoint{path};
        } catch (const std::invalid_argument& e) {
            CHECK(std::string(e.what()).size() < 600);
        }
    }
    // One line without its newline that is not a piece of the header: another program's file,
    // refused untouched (before: cut to nothing as a "torn" line, then written over).
    spit(path, "my notes, one line");
    CHECK_INVALID(Checkpoint{path}, path + " line 1: the first line is not the header");
    CHECK(slurp(path) == "my notes, one line");
    spit(path, "{\"format\":\"hovering-che");  // a torn header: cut off
    {
        Checkpoint c(path);
        CHECK(!c.torn().empty());
    }
    CHECK(slurp(path).empty());
    fs::remove_all(fs::path(path).parent_path());
}
