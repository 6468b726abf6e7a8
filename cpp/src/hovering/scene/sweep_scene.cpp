// The sweep kinds of the scene files read without Python. The specification is
// python/hovering/scenes/schema.py (parse_scene(..., check_output=False) after load_scene's file
// checks): the same keys, defaults, ranges, order of the checks and message texts, so that a scene
// fails in the same words whichever program reads it. tests/test_scene_cpp.py holds the two to it.
//
// Python's messages quote values with repr(), so this file reproduces repr() of what tomllib
// would have returned, Python's float repr and '.6g' formatting, the restricted expression
// language of _real (CPython's tokenizer and float semantics), matplotlib's is_color_like and the
// checks of the objects Python builds to validate (TruncatedMap, StepSystem), which are the core's.
#include "hovering/scene/sweep_scene.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "hovering/flow/potential.hpp"
#include "hovering/flow/system.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering::scene {

namespace {

struct IdentRange {
    char32_t first, last;
    char ascii;   // the NFKC form of `first`; the range maps on in step
    bool start;   // may begin an identifier (XID_Start)
};

#include "python_tables.inc"  // colour names and the Unicode tables of repr(), float() and identifiers

// ------------------------------------------------------------------------------------------------
// Text

constexpr double kPi = 3.141592653589793238;  // math.pi
constexpr std::size_t kMaxSceneBytes = 1 << 20;  // MAX_SCENE_BYTES
constexpr std::size_t kMaxPanels = 36;           // MAX_PANELS (also the most series)
constexpr std::size_t kMaxSeriesPoints = 200;    // MAX_SERIES_POINTS
constexpr std::size_t kMaxExpr = 200;            // _MAX_EXPR
constexpr std::size_t kMaxText = 200;            // MAX_TEXT (a text drawn on the figure)
constexpr std::size_t kMaxPathChars = 4096;      // MAX_PATH_CHARS
constexpr double kMaxCanvasPixels = 150e6;       // MAX_CANVAS_PIXELS

[[noreturn]] void fail(const std::string& msg) { throw std::invalid_argument(msg); }

/// Code points of UTF-8 text (toml++ and load_sweep_scene have validated it; a stray byte is kept as
/// itself so nothing here can read past the end).
std::u32string decode(std::string_view s) {
    std::u32string out;
    out.reserve(s.size());
    for (std::size_t i = 0; i < s.size();) {
        const auto b = static_cast<unsigned char>(s[i]);
        const int n = b < 0x80 ? 0 : b >= 0xF0 ? 3 : b >= 0xE0 ? 2 : b >= 0xC0 ? 1 : -1;
        if (n <= 0 || i + n >= s.size()) {
            out.push_back(b);
            ++i;
            continue;
        }
        char32_t c = b & (0x3F >> n);
        for (int k = 1; k <= n; ++k) c = (c << 6) | (static_cast<unsigned char>(s[i + k]) & 0x3F);
        out.push_back(c);
        i += n + 1;
    }
    return out;
}

/// Offset of the first byte Python's strict UTF-8 decoder refuses (the start of the bad sequence,
/// as UnicodeDecodeError.start), or npos for valid UTF-8.
std::size_t utf8_error(std::string_view s) {
    const auto byte = [&](std::size_t i) { return i < s.size() ? static_cast<unsigned char>(s[i]) : 0x100u; };
    for (std::size_t i = 0; i < s.size();) {
        const unsigned b = byte(i);
        if (b < 0x80) {
            ++i;
            continue;
        }
        int n;
        unsigned lo = 0x80, hi = 0xBF;  // the allowed range of the second byte
        if (b >= 0xC2 && b <= 0xDF) n = 1;
        else if (b >= 0xE0 && b <= 0xEF) n = 2, lo = b == 0xE0 ? 0xA0 : 0x80, hi = b == 0xED ? 0x9F : 0xBF;
        else if (b >= 0xF0 && b <= 0xF4) n = 3, lo = b == 0xF0 ? 0x90 : 0x80, hi = b == 0xF4 ? 0x8F : 0xBF;
        else return i;
        if (byte(i + 1) < lo || byte(i + 1) > hi) return i;
        for (int k = 2; k <= n; ++k)
            if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return i;
        i += n + 1;
    }
    return std::string::npos;
}

bool py_isspace(char32_t c) { return std::find(kPySpace.begin(), kPySpace.end(), c) != kPySpace.end(); }

bool py_isprintable(char32_t c) {
    const auto it = std::upper_bound(kNonPrintable.begin(), kNonPrintable.end(), c,
                                     [](char32_t x, const std::pair<char32_t, char32_t>& r) { return x < r.first; });
    return it == kNonPrintable.begin() || c > std::prev(it)->second;
}

/// The ASCII digit of a Unicode decimal digit (category Nd), or -1.
int decimal_digit(char32_t c) {
    const auto it = std::upper_bound(kDecimalZeros.begin(), kDecimalZeros.end(), c);
    if (it == kDecimalZeros.begin()) return -1;
    const char32_t zero = *std::prev(it);
    return c - zero < 10 ? static_cast<int>(c - zero) : -1;
}

bool is_ascii_digit(char32_t c) { return c >= '0' && c <= '9'; }
bool is_ascii_alpha(char32_t c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }

// ------------------------------------------------------------------------------------------------
// Python's repr() and formats

/// repr(float): the shortest digits that round-trip, in fixed notation for exponents -4 <= e < 16.
std::string py_float(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific);
    std::string s(buf, r.ptr);  // [-]d[.ddd]e(+|-)XX
    std::string sign;
    if (s[0] == '-') sign = "-", s.erase(0, 1);
    const auto e = s.find('e');
    const int exp = std::atoi(s.c_str() + e + 1);
    std::string digits = s.substr(0, e);
    digits.erase(std::remove(digits.begin(), digits.end(), '.'), digits.end());
    const int n = static_cast<int>(digits.size()), decpt = exp + 1;
    std::string out;
    if (decpt > -4 && decpt <= 16) {
        if (decpt <= 0) out = "0." + std::string(-decpt, '0') + digits;
        else if (decpt >= n) out = digits + std::string(decpt - n, '0') + ".0";
        else out = digits.substr(0, decpt) + "." + digits.substr(decpt);
    } else {
        out = digits.substr(0, 1) + (n > 1 ? "." + digits.substr(1) : "");
        char eb[16];
        std::snprintf(eb, sizeof eb, "e%c%02d", exp < 0 ? '-' : '+', std::abs(exp));
        out += eb;
    }
    return sign + out;
}

/// format(v, '.6g'): C's %.6g, but NaN without a sign as Python writes it.
std::string py_g6(double v) {
    if (std::isnan(v)) return "nan";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

void append_utf8(std::string& out, char32_t c) {
    if (c < 0x80) {
        out += static_cast<char>(c);
    } else if (c < 0x800) {
        out += static_cast<char>(0xC0 | (c >> 6));
        out += static_cast<char>(0x80 | (c & 0x3F));
    } else if (c < 0x10000) {
        out += static_cast<char>(0xE0 | (c >> 12));
        out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (c & 0x3F));
    } else {
        out += static_cast<char>(0xF0 | (c >> 18));
        out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
        out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (c & 0x3F));
    }
}

/// repr(str): single quotes unless the text has ' and no ", escapes for the quote, backslash,
/// \t \n \r, other control characters and whatever str.isprintable() refuses.
std::string py_str(std::string_view s) {
    const std::u32string u = decode(s);
    const bool has1 = u.find(U'\'') != std::u32string::npos, has2 = u.find(U'"') != std::u32string::npos;
    const char q = has1 && !has2 ? '"' : '\'';
    std::string out(1, q);
    for (const char32_t c : u) {
        char buf[16];
        if (c == static_cast<char32_t>(q) || c == U'\\') out += '\\', out += static_cast<char>(c);
        else if (c == U'\t') out += "\\t";
        else if (c == U'\n') out += "\\n";
        else if (c == U'\r') out += "\\r";
        else if (c < 0x20 || c == 0x7F) std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned>(c)), out += buf;
        else if (c < 0x7F || py_isprintable(c)) append_utf8(out, c);
        else if (c <= 0xFF) std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned>(c)), out += buf;
        else if (c <= 0xFFFF) std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c)), out += buf;
        else std::snprintf(buf, sizeof buf, "\\U%08x", static_cast<unsigned>(c)), out += buf;
    }
    return out + q;
}

/// A table's entries in the order tomllib's dict has them (where each key first appears): toml++
/// keeps a table sorted by key, and Python's messages list unknown keys and dict reprs in file order.
std::vector<std::pair<std::string_view, const toml::node*>> entries(const toml::table& t) {
    struct E {
        toml::source_position pos;
        std::string_view key;
        const toml::node* node;
    };
    std::vector<E> v;
    for (const auto& [k, n] : t) v.push_back({k.source().begin, k.str(), &n});
    std::stable_sort(v.begin(), v.end(), [](const E& a, const E& b) { return a.pos < b.pos; });
    std::vector<std::pair<std::string_view, const toml::node*>> out;
    for (const auto& e : v) out.emplace_back(e.key, e.node);
    return out;
}

std::string py_timedelta(long seconds) {
    long days = seconds / 86400, rest = seconds % 86400;
    if (rest < 0) rest += 86400, --days;
    std::string args;
    if (days) args += "days=" + std::to_string(days);
    if (rest) args += std::string(args.empty() ? "" : ", ") + "seconds=" + std::to_string(rest);
    return "datetime.timedelta(" + (args.empty() ? "0" : args) + ")";
}

std::string py_time_args(const toml::time& t) {
    std::string s = std::to_string(t.hour) + ", " + std::to_string(t.minute);
    const unsigned us = t.nanosecond / 1000;  // tomllib keeps microseconds, truncated
    if (t.second || us) s += ", " + std::to_string(t.second);
    if (us) s += ", " + std::to_string(us);
    return s;
}

std::string py_date_args(const toml::date& d) {
    return std::to_string(d.year) + ", " + std::to_string(d.month) + ", " + std::to_string(d.day);
}

/// repr() of the value tomllib returns for a TOML node (int, float, str, bool, list, dict and
/// the datetime classes).
std::string py_repr(const toml::node& n) {
    switch (n.type()) {
        case toml::node_type::string: return py_str(n.as_string()->get());
        case toml::node_type::integer: return std::to_string(n.as_integer()->get());
        case toml::node_type::floating_point: return py_float(n.as_floating_point()->get());
        case toml::node_type::boolean: return n.as_boolean()->get() ? "True" : "False";
        case toml::node_type::array: {
            std::string s = "[";
            for (const auto& e : *n.as_array()) s += (s.size() > 1 ? ", " : "") + py_repr(e);
            return s + "]";
        }
        case toml::node_type::table: {
            std::string s = "{";
            for (const auto& [k, v] : entries(*n.as_table())) s += (s.size() > 1 ? ", " : "") + py_str(k) + ": " + py_repr(*v);
            return s + "}";
        }
        case toml::node_type::date: return "datetime.date(" + py_date_args(n.as_date()->get()) + ")";
        case toml::node_type::time: return "datetime.time(" + py_time_args(n.as_time()->get()) + ")";
        case toml::node_type::date_time: {
            const toml::date_time& dt = n.as_date_time()->get();
            std::string s = "datetime.datetime(" + py_date_args(dt.date) + ", " + py_time_args(dt.time);
            if (dt.offset) {
                const long sec = 60L * dt.offset->minutes;
                s += ", tzinfo=" + (sec == 0 ? std::string("datetime.timezone.utc")
                                             : "datetime.timezone(" + py_timedelta(sec) + ")");
            }
            return s + ")";
        }
        default: return "None";
    }
}

/// repr() of a list of str (e.g. ['atol', 'rtol']).
std::string py_list(const std::vector<std::string_view>& v) {
    std::string s = "[";
    for (const auto& x : v) s += (s.size() > 1 ? ", " : "") + py_str(x);
    return s + "]";
}

/// ', '.join(repr(c) for c in choices).
std::string py_choices(const std::vector<std::string_view>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + py_str(x);
    return s;
}

// ------------------------------------------------------------------------------------------------
// Numbers as Python reads them

/// A correctly rounded double from decimal digits times 10^exp10 (strtod without a decimal point,
/// so the C locale's separator cannot matter); exp10 is clamped far beyond the double range.
double decimal_value(const std::string& digits, long long exp10) {
    const bool zero = digits.find_first_not_of('0') == std::string::npos;
    if (zero) return 0.0;
    exp10 = std::clamp(exp10, -100000LL, 100000LL);
    const std::string s = digits + "e" + std::to_string(exp10);
    return std::strtod(s.c_str(), nullptr);
}

/// An integer's exact bits to the nearest double (ties to even, as int.__float__); inf if it overflows.
double bits_value(const std::string& bits) {
    const auto first = bits.find('1');
    if (first == std::string::npos) return 0.0;
    const std::string b = bits.substr(first);
    if (b.size() > 1100) return HUGE_VAL;
    const std::size_t keep = std::min<std::size_t>(b.size(), 53);
    std::uint64_t m = 0;
    for (std::size_t i = 0; i < keep; ++i) m = (m << 1) | static_cast<std::uint64_t>(b[i] == '1');
    if (b.size() > keep) {
        const bool half = b[keep] == '1', sticky = b.find('1', keep + 1) != std::string::npos;
        if (half && (sticky || (m & 1))) ++m;
    }
    return std::ldexp(static_cast<double>(m), static_cast<int>(b.size() - keep));
}

/// float(s) for a str as Python 3.11 reads it: Unicode spaces and decimal digits first become
/// ASCII, underscores only between digits, spaces stripped, then a decimal (no hex) or
/// inf/infinity/nan with an optional sign; nullopt where Python raises ValueError.
std::optional<double> py_float_of(std::string_view text) {
    std::string s;
    for (const char32_t c : decode(text)) {
        if (py_isspace(c)) s += ' ';
        else if (c < 0x80) s += static_cast<char>(c);
        else if (const int d = decimal_digit(c); d >= 0) s += static_cast<char>('0' + d);
        else return std::nullopt;
    }
    if (s.find('_') != std::string::npos) {
        std::string t;
        char prev = 0;
        for (const char c : s) {
            if (c == '_' && !is_ascii_digit(prev)) return std::nullopt;
            if (c != '_' && prev == '_' && !is_ascii_digit(c)) return std::nullopt;
            if (c != '_') t += c;
            prev = c;
        }
        if (prev == '_') return std::nullopt;
        s = t;
    }
    const auto ws = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; };
    std::size_t a = 0, b = s.size();
    while (a < b && ws(s[a])) ++a;
    while (b > a && ws(s[b - 1])) --b;
    std::string t = s.substr(a, b - a);
    double sign = 1.0;
    std::size_t i = 0;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) sign = t[i] == '-' ? -1.0 : 1.0, ++i;
    std::string rest = t.substr(i);
    std::transform(rest.begin(), rest.end(), rest.begin(), [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); });
    if (rest == "inf" || rest == "infinity") return sign * HUGE_VAL;
    if (rest == "nan") return std::nan("");
    std::string digits, exp;
    std::size_t j = 0, frac = 0;
    bool any = false;
    while (j < rest.size() && is_ascii_digit(rest[j])) digits += rest[j++], any = true;
    if (j < rest.size() && rest[j] == '.') {
        ++j;
        while (j < rest.size() && is_ascii_digit(rest[j])) digits += rest[j++], ++frac, any = true;
    }
    if (!any) return std::nullopt;
    long long e10 = 0;
    if (j < rest.size() && rest[j] == 'e') {
        ++j;
        bool neg = false;
        if (j < rest.size() && (rest[j] == '+' || rest[j] == '-')) neg = rest[j] == '-', ++j;
        if (j >= rest.size() || !is_ascii_digit(rest[j])) return std::nullopt;
        while (j < rest.size() && is_ascii_digit(rest[j])) e10 = std::min(e10 * 10 + (rest[j++] - '0'), 1000000LL);
        if (neg) e10 = -e10;
    }
    if (j != rest.size()) return std::nullopt;
    return sign * decimal_value(digits, e10 - static_cast<long long>(frac));
}

// ------------------------------------------------------------------------------------------------
// The expressions of _real: ast.parse(value, mode="eval") walked by _eval_expr over floats. Every
// failure gives the same message in Python (syntax, an unsupported node, ZeroDivisionError, math
// domain and range errors, a complex power), so here one exception stands for them all; what must
// match exactly is which texts fail, which evaluate to a non-finite float, and the bits of the rest.

struct ExprError {};

/// DOUBLE_IS_ODD_INTEGER of CPython's float_pow.
bool odd_integer(double x) { return std::fmod(std::fabs(x), 2.0) == 1.0; }

/// float.__pow__ of CPython 3.11: its own special cases, then the C library's pow and its errno (a
/// negative base to a fractional power is a complex number in Python, which float() refuses).
double py_pow(double v, double w) {
    if (w == 0) return 1.0;
    if (std::isnan(v)) return v;
    if (std::isnan(w)) return v == 1.0 ? 1.0 : w;
    if (std::isinf(w)) {
        const double a = std::fabs(v);
        if (a == 1.0) return 1.0;
        return (w > 0.0) == (a > 1.0) ? std::fabs(w) : 0.0;
    }
    if (std::isinf(v)) {
        const bool odd = odd_integer(w);
        if (w > 0.0) return odd ? v : std::fabs(v);
        return odd ? std::copysign(0.0, v) : 0.0;
    }
    if (v == 0.0) {
        if (w < 0.0) throw ExprError{};  // ZeroDivisionError
        return odd_integer(w) ? v : 0.0;
    }
    bool negate = false;
    if (v < 0.0) {
        if (w != std::floor(w)) throw ExprError{};  // a complex result
        v = -v;
        negate = odd_integer(w);
    }
    if (v == 1.0) return negate ? -1.0 : 1.0;
    errno = 0;
    const double x = std::pow(v, w);
    int err = errno;
    if (err == 0 && (x == HUGE_VAL || x == -HUGE_VAL)) err = ERANGE;  // _Py_ADJUST_ERANGE1
    else if (err == ERANGE && x == 0.0) err = 0;
    if (err != 0) throw ExprError{};  // OverflowError
    return negate ? -x : x;
}

/// math_1 of CPython's math module (sqrt, sin, cos, acos): a NaN from a number or an infinity from a
/// finite argument is an error, as is an errno other than an underflow.
double py_math(double (*f)(double), double x) {
    errno = 0;
    const double r = f(x);
    const int err = errno;
    if (std::isnan(r) && !std::isnan(x)) throw ExprError{};
    if (std::isinf(r) && std::isfinite(x)) throw ExprError{};
    if (std::isfinite(r) && err != 0 && !(err == ERANGE && std::fabs(r) < 1.5)) throw ExprError{};
    return r;
}

/// The ASCII character an identifier character stands for after Python's NFKC normalisation, or 0.
char ident_char(char32_t c, bool first) {
    if (is_ascii_alpha(c) || c == U'_') return static_cast<char>(c);
    if (is_ascii_digit(c)) return first ? 0 : static_cast<char>(c);
    if (c < 0x80) return 0;
    const auto it = std::upper_bound(kIdentAscii.begin(), kIdentAscii.end(), c,
                                     [](char32_t x, const IdentRange& r) { return x < r.first; });
    if (it == kIdentAscii.begin()) return 0;
    const IdentRange& r = *std::prev(it);
    if (c > r.last || (first && !r.start)) return 0;
    return static_cast<char>(r.ascii + (c - r.first));
}

/// Python's tokenizer (CPython 3.11: indentation, continuation lines, comments, number literals)
/// and the part of its grammar whose trees _eval_expr accepts, evaluated as it is parsed.
class Expression {
public:
    explicit Expression(const std::u32string& text) {
        // Source text reaches the tokenizer with \r\n and \r read as \n; a NUL is refused outright.
        for (std::size_t i = 0; i < text.size(); ++i) {
            if (text[i] == 0) throw ExprError{};
            if (text[i] == U'\r') {
                s_ += U'\n';
                if (i + 1 < text.size() && text[i + 1] == U'\n') ++i;
            } else {
                s_ += text[i];
            }
        }
    }

    double evaluate() {
        tokenize();
        const Item it = sum();
        if (peek().kind != Kind::Newline && peek().kind != Kind::End) throw ExprError{};
        return value_of(it);
    }

private:
    enum class Kind { Number, Name, Op, Newline, End };
    struct Token {
        Kind kind;
        double value = 0;
        std::string text;
    };
    // A parsed operand: a number, or a bare name (still a name through parentheses: "(sqrt)(4)" calls
    // sqrt) that becomes pi, OMEGA_G or a function by how it is used.
    struct Item {
        bool is_name = false;
        double value = 0;
        std::string name;
    };

    std::u32string s_;
    std::size_t i_ = 0;
    std::vector<Token> toks_;
    std::size_t pos_ = 0;

    char32_t at(std::size_t j) const { return j < s_.size() ? s_[j] : 0; }

    /// A backslash must end its line, and a line must follow (CPython's tok_continuation_line).
    void continuation() {
        if (at(i_ + 1) != U'\n') throw ExprError{};
        i_ += 2;
        if (i_ >= s_.size()) throw ExprError{};
    }

    void tokenize() {
        int level = 0;
        bool bol = true, ended = false;
        for (;;) {
            bool blank = false;
            if (bol) {
                // Indentation: the first backslash-joined column, else the line's own, must be 0
                // for a line with code (one expression: any indent is an IndentationError).
                bol = false;
                int col = 0, cont = 0;
                for (;;) {
                    const char32_t c = at(i_);
                    if (c == U' ') ++col, ++i_;
                    else if (c == U'\t') col = (col / 8 + 1) * 8, ++i_;
                    else if (c == U'\f') col = 0, ++i_;
                    else if (c == U'\\') {
                        if (!cont) cont = col;
                        continuation();
                    } else break;
                }
                blank = at(i_) == U'#' || at(i_) == U'\n';
                if (!blank && level == 0 && (cont ? cont : col) != 0) throw ExprError{};
            }
            for (;;) {
                while (at(i_) == U' ' || at(i_) == U'\t' || at(i_) == U'\f') ++i_;
                if (at(i_) == U'#')
                    while (i_ < s_.size() && s_[i_] != U'\n') ++i_;
                if (i_ >= s_.size()) {
                    if (level) throw ExprError{};
                    toks_.push_back({Kind::End, 0, {}});
                    return;
                }
                const char32_t c = s_[i_];
                if (c == U'\n') {
                    ++i_;
                    bol = true;
                    if (!blank && level == 0) toks_.push_back({Kind::Newline, 0, {}}), ended = true;
                    break;
                }
                if (c == U'\\') {
                    continuation();
                    continue;
                }
                if (ended) throw ExprError{};  // code after the expression's line: a second statement
                if (is_ascii_digit(c) || (c == U'.' && is_ascii_digit(at(i_ + 1)))) {
                    toks_.push_back({Kind::Number, number(), {}});
                } else if (ident_char(c, true) || c >= 0x80) {
                    std::string name;
                    while (at(i_) >= 0x80 || ident_char(at(i_), name.empty())) {
                        const char a = ident_char(at(i_), name.empty());
                        if (!a) throw ExprError{};  // not an identifier, or none that normalises to ASCII
                        name += a;
                        ++i_;
                    }
                    toks_.push_back({Kind::Name, 0, name});
                } else {
                    // Python has more operators, but none that _eval_expr evaluates.
                    std::string op;
                    if (c == U'*' && at(i_ + 1) == U'*') op = "**";
                    else if (c < 0x80 && std::strchr("+-*/(),", static_cast<int>(c))) op = std::string(1, static_cast<char>(c));
                    else throw ExprError{};
                    if (op == "(") ++level;
                    if (op == ")" && level-- == 0) throw ExprError{};  // unmatched ')'
                    i_ += op.size();
                    toks_.push_back({Kind::Op, 0, op});
                }
            }
        }
    }

    /// Digits of tok_decimal_tail: digit runs joined by single underscores.
    void decimal_tail(std::string& digits) {
        for (;;) {
            while (is_ascii_digit(at(i_))) digits += static_cast<char>(at(i_++));
            if (at(i_) != U'_') return;
            ++i_;
            if (!is_ascii_digit(at(i_))) throw ExprError{};
        }
    }

    /// verify_end_of_number: a literal followed by a letter, digit or '_' is an error (and the
    /// keywords Python lets through with a warning only lead to trees _eval_expr refuses).
    void end_of_number() const {
        const char32_t c = at(i_);
        if (is_ascii_alpha(c) || is_ascii_digit(c) || c == U'_' || c >= 0x80) throw ExprError{};
    }

    /// A number literal as float(node.value): ints (any base) exactly rounded and refused when too
    /// large for a double (OverflowError), floats rounded as the parser does (1e400 is inf).
    double number() {
        const char32_t c0 = at(i_), c1 = at(i_ + 1);
        if (c0 == U'0' && (c1 == U'x' || c1 == U'X' || c1 == U'o' || c1 == U'O' || c1 == U'b' || c1 == U'B')) {
            const int base = (c1 == U'x' || c1 == U'X') ? 16 : (c1 == U'o' || c1 == U'O') ? 8 : 2;
            const int width = base == 16 ? 4 : base == 8 ? 3 : 1;
            const auto digit = [&](char32_t c) -> int {
                int d = -1;
                if (is_ascii_digit(c)) d = static_cast<int>(c - U'0');
                else if (c >= U'a' && c <= U'f') d = static_cast<int>(c - U'a') + 10;
                else if (c >= U'A' && c <= U'F') d = static_cast<int>(c - U'A') + 10;
                return d < base ? d : -1;
            };
            i_ += 2;
            std::string bits;
            do {
                if (at(i_) == U'_') ++i_;
                if (digit(at(i_)) < 0) throw ExprError{};
                for (int d; (d = digit(at(i_))) >= 0; ++i_)
                    for (int k = width - 1; k >= 0; --k) bits += ((d >> k) & 1) ? '1' : '0';
            } while (at(i_) == U'_');
            end_of_number();
            const double v = bits_value(bits);
            if (std::isinf(v)) throw ExprError{};
            return v;
        }
        std::string int_digits, frac_digits;
        bool is_float = false;
        long long exp10 = 0;
        if (c0 == U'0') {
            // "0", "00", "0_0"; other digits after leading zeros only before '.', 'e' or 'j'.
            for (;;) {
                if (at(i_) == U'_') {
                    ++i_;
                    if (!is_ascii_digit(at(i_))) throw ExprError{};
                }
                if (at(i_) != U'0') break;
                int_digits += '0';
                ++i_;
            }
            const bool nonzero = is_ascii_digit(at(i_));
            if (nonzero) decimal_tail(int_digits);
            const char32_t c = at(i_);
            if (nonzero && c != U'.' && c != U'e' && c != U'E' && c != U'j' && c != U'J') throw ExprError{};
        } else if (c0 != U'.') {
            decimal_tail(int_digits);
        }
        if (at(i_) == U'.') {
            is_float = true;
            ++i_;
            if (is_ascii_digit(at(i_))) decimal_tail(frac_digits);
        }
        if (at(i_) == U'e' || at(i_) == U'E') {
            is_float = true;
            ++i_;
            bool neg = false;
            if (at(i_) == U'+' || at(i_) == U'-') neg = at(i_++) == U'-';
            if (!is_ascii_digit(at(i_))) throw ExprError{};
            std::string e;
            decimal_tail(e);
            for (const char d : e) exp10 = std::min(exp10 * 10 + (d - '0'), 1000000LL);
            if (neg) exp10 = -exp10;
        }
        if (at(i_) == U'j' || at(i_) == U'J') throw ExprError{};  // imaginary: a complex constant
        end_of_number();
        const double v = decimal_value(int_digits + frac_digits, exp10 - static_cast<long long>(frac_digits.size()));
        if (!is_float && std::isinf(v)) throw ExprError{};
        return v;
    }

    const Token& peek() const { return toks_[pos_]; }
    bool is_op(const char* op) const { return peek().kind == Kind::Op && peek().text == op; }
    void expect(const char* op) {
        if (!is_op(op)) throw ExprError{};
        ++pos_;
    }
    static Item number_item(double v) { return Item{false, v, {}}; }

    static double value_of(const Item& it) {
        if (!it.is_name) return it.value;
        if (it.name == "pi") return kPi;
        if (it.name == "OMEGA_G") return kOmegaG;
        throw ExprError{};
    }

    Item atom() {
        const Token t = peek();
        if (t.kind == Kind::Number) return ++pos_, number_item(t.value);
        if (t.kind == Kind::Name) return ++pos_, Item{true, 0, t.text};
        if (is_op("(")) {
            ++pos_;
            Item it = sum();
            expect(")");
            return it;
        }
        throw ExprError{};
    }

    Item primary() {
        Item it = atom();
        while (is_op("(")) {
            ++pos_;
            double (*f)(double) = nullptr;
            if (it.is_name && it.name == "sqrt") f = [](double x) { return std::sqrt(x); };
            else if (it.is_name && it.name == "sin") f = [](double x) { return std::sin(x); };
            else if (it.is_name && it.name == "cos") f = [](double x) { return std::cos(x); };
            else if (it.is_name && it.name == "acos") f = [](double x) { return std::acos(x); };
            else throw ExprError{};
            const Item arg = sum();
            if (is_op(",")) ++pos_;
            expect(")");
            it = number_item(py_math(f, value_of(arg)));
        }
        return it;
    }

    Item power() {
        Item base = primary();
        if (!is_op("**")) return base;
        ++pos_;
        const Item e = factor();  // right-associative, and "2**-1" is allowed
        return number_item(py_pow(value_of(base), value_of(e)));
    }

    Item factor() {
        if (is_op("+") || is_op("-")) {
            const bool neg = peek().text == "-";
            ++pos_;
            const double v = value_of(factor());
            return number_item(neg ? -v : v);
        }
        return power();
    }

    Item term() {
        Item left = factor();
        while (is_op("*") || is_op("/")) {
            const bool div = peek().text == "/";
            ++pos_;
            const double a = value_of(left), b = value_of(factor());
            if (div && b == 0.0) throw ExprError{};  // ZeroDivisionError
            left = number_item(div ? a / b : a * b);
        }
        return left;
    }

    Item sum() {
        Item left = term();
        while (is_op("+") || is_op("-")) {
            const bool sub = peek().text == "-";
            ++pos_;
            const double a = value_of(left), b = value_of(term());
            left = number_item(sub ? a - b : a + b);
        }
        return left;
    }
};

// ------------------------------------------------------------------------------------------------
// matplotlib.colors.is_color_like for a str

bool colour_name(std::string_view s) { return std::binary_search(kColourNames.begin(), kColourNames.end(), s); }

/// is_color_like(s): 'C<digits>', 'none' in any case, a colour name (as given, or lowercased unless
/// it is one character: 'B' is no colour), hex of 3, 4, 6 or 8 digits, or a grey level float(s)
/// in [0, 1]. str.lower() of a non-ASCII character gives ASCII only for the Kelvin sign.
bool is_color_like(std::string_view s) {
    const std::u32string u = decode(s);
    if (u.size() >= 2 && u[0] == U'C' && std::all_of(u.begin() + 1, u.end(), is_ascii_digit)) return true;
    std::string lower;
    for (const char32_t c : u) {
        if (c == 0x212A) lower += 'k';
        else if (c >= U'A' && c <= U'Z') lower += static_cast<char>(c - U'A' + U'a');
        else append_utf8(lower, c);
    }
    if (lower == "none") return true;
    if (colour_name(s) || (u.size() != 1 && colour_name(lower))) return true;
    if (u.size() > 1 && u[0] == U'#' &&
        std::all_of(u.begin() + 1, u.end(), [](char32_t c) { return c < 0x80 && std::isxdigit(static_cast<int>(c)); }))
        return u.size() == 4 || u.size() == 5 || u.size() == 7 || u.size() == 9;
    const std::optional<double> grey = py_float_of(s);
    return grey && *grey >= 0 && *grey <= 1;
}

// ------------------------------------------------------------------------------------------------
// Value checks of schema.py: _real, _int, _str, _color, _table, _tables, _eps_list, _check_keys

using Keys = std::vector<std::string_view>;

const Keys kKinds{"portrait", "critical_orbits", "hovering_area", "flow_portrait",
                  "flow_hovering_area", "tangent_tori", "sigma_structure"};
const Keys kMapKeys{"Omega0", "theta_w", "tau0", "tau1", "lam"};
const Keys kHovKeys{"kind", "title", "output", "dpi", "figsize", "map", "n_steps", "samples", "seed", "eps", "series"};
const Keys kSeriesKeys{"label", "golden_c", "color", "K_low", "Omega0", "theta_w", "tau0", "tau1", "lam"};
const Keys kFlowHovKeys{"kind",       "title",   "output",  "dpi", "figsize", "system",  "section",
                        "integrator", "outputs", "n_steps", "eps", "samples", "seed",    "models"};
const Keys kSystemKeys{"V1", "V2", "coupling", "eps", "qw1", "qw2", "geometry"};
const Keys kPotentialKeys{"kind", "omega", "alpha"};
const Keys kIntegratorKeys{"stepper", "rtol", "atol", "accuracy"};
const Keys kOutputsKeys{"record", "trajectory_dt"};
const Keys kSteppers{"rk8pd", "rkck", "rkf45", "rk4", "rk2", "msadams", "rk4imp", "rk2imp", "exact"};  // flow.section.STEPPERS

/// An interval of _real (None ends as nullopt).
struct Bounds {
    std::optional<double> lo, hi;
    bool lo_open = false, hi_open = false;
};

std::string join(const Keys& keys) {
    std::string s;
    for (const auto& k : keys) s += (s.empty() ? "" : ", ") + std::string(k);
    return s;
}

bool contains(const Keys& keys, std::string_view k) { return std::find(keys.begin(), keys.end(), k) != keys.end(); }

/// _real: a finite number, or an expression string, inside an interval.
double real(const std::string& where, const toml::node& value, const Bounds& b = {}) {
    double v = 0;
    if (value.is_string()) {
        const std::u32string u = decode(value.as_string()->get());
        if (u.size() > kMaxExpr)
            fail(where + ": expression of " + std::to_string(u.size()) + " characters; allowed: at most " +
                 std::to_string(kMaxExpr));
        try {
            v = Expression(u).evaluate();
        } catch (const ExprError&) {
            fail(where + ": cannot evaluate " + py_repr(value) +
                 "; allowed: a number or an expression of numbers, pi, OMEGA_G, + - * / ** and sqrt, sin, cos, acos");
        }
    } else if (value.is_integer()) {
        v = static_cast<double>(value.as_integer()->get());
    } else if (value.is_floating_point()) {
        v = value.as_floating_point()->get();
    } else {
        fail(where + " must be a number, got " + py_repr(value));
    }
    if (!std::isfinite(v)) fail(where + " must be finite, got " + py_repr(value));
    const bool bad_lo = b.lo && (b.lo_open ? v <= *b.lo : v < *b.lo);
    const bool bad_hi = b.hi && (b.hi_open ? v >= *b.hi : v > *b.hi);
    if (bad_lo || bad_hi) {
        const std::string rng = std::string(b.lo_open || !b.lo ? "(" : "[") + (b.lo ? py_float(*b.lo) : "-inf") + ", " +
                                (b.hi ? py_float(*b.hi) : "inf") + (b.hi_open || !b.hi ? ")" : "]");
        fail(where + " = " + py_repr(value) + " is out of range; allowed: " + rng);
    }
    return v;
}

/// _int: an integer (not a bool or a float) in [lo, hi] (hi: none).
std::int64_t integer(const std::string& where, const toml::node& value, std::int64_t lo,
                     std::optional<std::int64_t> hi = std::nullopt) {
    if (!value.is_integer()) fail(where + " must be an integer, got " + py_repr(value));
    const std::int64_t v = value.as_integer()->get();
    if (v < lo || (hi && v > *hi))
        fail(where + " = " + py_repr(value) + " is out of range; allowed: [" + std::to_string(lo) + ", " +
             (hi ? std::to_string(*hi) : "inf") + "]");
    return v;
}

/// _str: a string with something besides whitespace (str.strip()) of at most limit characters,
/// optionally one of choices.
std::string text(const std::string& where, const toml::node& value, const Keys* choices = nullptr,
                 std::size_t limit = kMaxText) {
    bool blank = true;
    if (value.is_string())
        for (const char32_t c : decode(value.as_string()->get())) blank = blank && py_isspace(c);
    if (blank) fail(where + " must be a non-empty string, got " + py_repr(value));
    const std::string& s = value.as_string()->get();
    const std::size_t n = decode(s).size();
    if (n > limit)
        fail(where + ": a string of " + std::to_string(n) + " characters; allowed: at most " + std::to_string(limit));
    if (choices && !contains(*choices, s))
        fail(where + " = " + py_repr(value) + " is not allowed; allowed: " + py_choices(*choices));
    return s;
}

std::string text(const std::string& where, const toml::node& value, const Keys& choices) {
    return text(where, value, &choices);
}

/// _color: a string matplotlib takes for a colour.
std::string colour(const std::string& where, const toml::node& value) {
    std::string s = text(where, value);
    if (!is_color_like(s))
        fail(where + " = " + py_repr(value) +
             " is not a matplotlib colour; allowed: a name ('red'), 'C0'..'C9', or hex '#rrggbb'");
    return s;
}

const toml::table& table(const std::string& where, const toml::node& value) {
    if (!value.is_table()) fail(where + " must be a table, got " + py_repr(value));
    return *value.as_table();
}

/// _tables: a non-empty array of at most MAX_PANELS tables ([[what]]; the entries are checked later).
const toml::array& tables(const std::string& where, const toml::node& value, const std::string& what) {
    if (!value.is_array() || value.as_array()->empty())
        fail(where + " must be a non-empty array of tables ([[" + what + "]]), got " + py_repr(value));
    const toml::array& a = *value.as_array();
    if (a.size() > kMaxPanels)
        fail(where + ": " + std::to_string(a.size()) + " " + what + "; allowed: at most " + std::to_string(kMaxPanels) +
             " (one figure)");
    return a;
}

/// _eps_list: distinct numbers, at most MAX_SERIES_POINTS.
std::vector<double> eps_list(const std::string& where, const toml::node& value, const Bounds& b = {}) {
    if (!value.is_array() || value.as_array()->empty())
        fail(where + " must be a non-empty list of numbers, got " + py_repr(value));
    const toml::array& a = *value.as_array();
    if (a.size() > kMaxSeriesPoints)
        fail(where + ": " + std::to_string(a.size()) + " values; allowed: at most " + std::to_string(kMaxSeriesPoints) +
             " (use a sweep for more)");
    std::vector<double> eps;
    for (std::size_t i = 0; i < a.size(); ++i) eps.push_back(real(where + "[" + std::to_string(i) + "]", a[i], b));
    for (std::size_t i = 0; i < eps.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            if (eps[i] == eps[j]) fail(where + " = " + py_repr(value) + " lists a value twice");  // 0.0 == -0.0 in a set too
    return eps;
}

/// _check_keys: unknown keys (in file order), then the required ones in the order given.
void check_keys(const std::string& where, const toml::table& t, const Keys& allowed, const Keys& required = {}) {
    Keys unknown;
    for (const auto& [k, v] : entries(t))
        if (!contains(allowed, k)) unknown.push_back(k);
    if (!unknown.empty())
        fail(where + ": unknown key(s) " + py_choices(unknown) + "; allowed keys: " + join(allowed));
    for (const auto& k : required)
        if (!t.contains(k)) fail(where + ": missing required key " + py_str(k) + "; allowed keys: " + join(allowed));
}

const toml::node* get(const toml::table& t, std::string_view k) { return t.get(k); }

// ------------------------------------------------------------------------------------------------
// Paths: what pathlib makes of a path string

/// str(PurePosixPath(p)): empty and '.' parts dropped, two leading slashes kept (POSIX leaves them
/// to the system), any other run of them one.
std::string posix_path(const std::string& p) {
    std::string root;
    std::size_t start = 0;
    if (!p.empty() && p[0] == '/') {
        start = std::min(p.find_first_not_of('/'), p.size());
        root = start == 2 ? "//" : "/";
    }
    std::string out = root;
    bool first = true;
    for (std::size_t i = start; i <= p.size();) {
        std::size_t j = std::min(p.find('/', i), p.size());
        const std::string part = p.substr(i, j - i);
        if (!part.empty() && part != ".") out += (first ? "" : "/") + part, first = false;
        i = j + 1;
    }
    return out.empty() ? "." : out;
}

/// PurePath.name of a normalised path ("" for "/" or ".").
std::string path_name(const std::string& normalised) {
    const auto slash = normalised.rfind('/');
    std::string name = slash == std::string::npos ? normalised : normalised.substr(slash + 1);
    return name == "." ? "" : name;
}

/// PurePath.stem: the name without its last suffix (a leading or trailing dot is no suffix).
std::string path_stem(const std::string& name) {
    const auto i = name.rfind('.');
    return i != std::string::npos && i > 0 && i + 1 < name.size() ? name.substr(0, i) : name;
}

// ------------------------------------------------------------------------------------------------
// The kinds

/// The five map keys of a table as far as given (optional: absent).
using MapValues = std::array<std::optional<double>, 5>;

/// _map_params: the map keys present, in _MAP_KEYS order (theta_w in (0, pi), lam > 0).
void map_params(const std::string& where, const toml::table& t, MapValues& into) {
    const std::array<Bounds, 5> ranges{Bounds{}, Bounds{0.0, kPi, true, true}, Bounds{}, Bounds{},
                                       Bounds{0.0, std::nullopt, true, false}};
    for (std::size_t k = 0; k < kMapKeys.size(); ++k)
        if (const toml::node* v = get(t, kMapKeys[k])) into[k] = real(where + "." + std::string(kMapKeys[k]), *v, ranges[k]);
}

void parse_hovering_area(const std::string& where, const toml::table& root, SweepScene& s) {
    MapValues scene_map;
    if (const toml::node* m = get(root, "map")) {
        const toml::table& mt = table(where + ".map", *m);
        check_keys(where + ".map", mt, kMapKeys);
        map_params(where + ".map", mt, scene_map);
    }
    s.n_steps = integer(where + ".n_steps", *get(root, "n_steps"), 1, 10'000'000);
    s.eps = eps_list(where + ".eps", *get(root, "eps"));
    const toml::array& sv = tables(where + ".series", *get(root, "series"), "series");
    for (std::size_t i = 0; i < sv.size(); ++i) {
        const std::string sw = where + ".series[" + std::to_string(i) + "]";
        const toml::table& st = table(sw, sv[i]);
        check_keys(sw, st, kSeriesKeys, {"label"});
        MapValues vals{std::nullopt, std::nullopt, 1.0, 0.5, 0.5};  // _MAP_DEFAULTS
        for (std::size_t k = 0; k < vals.size(); ++k)
            if (scene_map[k]) vals[k] = scene_map[k];
        map_params(sw, st, vals);
        Series x;
        if (const toml::node* gc = get(st, "golden_c")) {
            for (const char* k : {"Omega0", "theta_w"})
                if (st.contains(k)) fail(sw + ": give either 'golden_c' or " + py_str(k) + ", not both");
            const double c = real(sw + ".golden_c", *gc);
            if (!(std::fabs(c) < std::fabs(*vals[2])))
                fail(sw + ".golden_c = " + py_repr(*gc) + " is out of range; allowed: |c| < |tau0| = " +
                     py_float(std::fabs(*vals[2])));
            x.golden = true;
            x.golden_c = c;
            vals[0] = vals[1] = std::numeric_limits<double>::quiet_NaN();
        } else {
            for (std::size_t k = 0; k < 2; ++k)
                if (!vals[k])
                    fail(sw + ": missing required key " + py_str(kMapKeys[k]) + " (in [map] or the series), or 'golden_c'");
        }
        x.label = text(sw + ".label", *get(st, "label"));
        if (const toml::node* c = get(st, "color")) x.color = colour(sw + ".color", *c);
        const toml::node* kl = get(st, "K_low");
        if (kl) {
            x.has_K_low = true;
            x.K_low = real(sw + ".K_low", *kl, Bounds{std::nullopt, 0.0, false, true});
        }
        x.map = MapParams{*vals[0], *vals[1], *vals[2], *vals[3], *vals[4]};
        // Python builds the map at every eps (SeriesSpec.map_at(e).build()): its checks, and the band.
        for (const double e : s.eps) {
            double floor = 0;
            try {
                const MapParams m = x.at(e);
                floor = make_truncated_map(e, m.Omega0, m.theta_w, m.tau0, m.tau1, m.lam).band().lo;
            } catch (const std::invalid_argument& err) {
                fail(sw + " at eps = " + py_float(e) + ": " + err.what());
            }
            if (kl && !(x.K_low > floor))
                fail(sw + ".K_low = " + py_repr(*kl) + " lies below the band floor " + py_g6(floor) +
                     " of the map at eps = " + py_float(e) + "; allowed: (" + py_g6(floor) + ", 0)");
        }
        s.series.push_back(std::move(x));
    }
    const toml::node* samples = get(root, "samples");
    s.samples = samples ? integer(where + ".samples", *samples, 1, 100'000'000) : 100'000;
    const toml::node* seed = get(root, "seed");
    s.seed = seed ? static_cast<std::uint64_t>(integer(where + ".seed", *seed, 0, INT64_MAX)) : 0;
}

PotentialSpec potential(const std::string& where, const toml::node& value) {
    const toml::table& t = table(where, value);
    check_keys(where, t, kPotentialKeys, {"kind", "omega"});
    PotentialSpec p;
    p.kind = text(where + ".kind", *get(t, "kind"), Keys{"harmonic", "tan"});
    const Bounds scale{1e-100, 1e100};
    p.omega = real(where + ".omega", *get(t, "omega"), scale);
    if (p.kind == "tan") {
        if (!t.contains("alpha")) fail(where + ": missing required key 'alpha' for kind = 'tan'");
        p.alpha = real(where + ".alpha", *get(t, "alpha"), scale);
    } else if (t.contains("alpha")) {
        fail(where + ": 'alpha' is only used with kind = 'tan', got kind = 'harmonic'");
    }
    return p;
}

std::vector<std::array<double, 3>> coupling(const std::string& where, const toml::node& value) {
    if (value.is_string() && value.as_string()->get() == "bilinear") return {{1.0, 1.0, 1.0}};
    if (value.is_string() && value.as_string()->get() == "none") return {};
    if (!value.is_array() || value.as_array()->empty() || value.as_array()->size() > 64)
        fail(where + " must be 'bilinear', 'none' or a list of 1..64 terms [c, i, j] (c q1^i q2^j), got " + py_repr(value));
    std::vector<std::array<double, 3>> terms;
    const toml::array& a = *value.as_array();
    for (std::size_t k = 0; k < a.size(); ++k) {
        const std::string tw = where + "[" + std::to_string(k) + "]";
        if (!a[k].is_array() || a[k].as_array()->size() != 3)
            fail(tw + " must be a term [c, i, j] (c q1^i q2^j), got " + py_repr(a[k]));
        const toml::array& term = *a[k].as_array();
        const double c = real(tw + "[0]", term[0]);
        const auto i = integer(tw + "[1]", term[1], 0, 20);
        const auto j = integer(tw + "[2]", term[2], 0, 20);
        terms.push_back({c, static_cast<double>(i), static_cast<double>(j)});
    }
    return terms;
}

std::shared_ptr<const Potential> build(const PotentialSpec& p) {
    if (p.kind == "tan") return std::make_shared<Tan>(p.omega, p.alpha);
    return std::make_shared<Harmonic>(p.omega);
}

/// _system: the [system] table, then what StepSystem checks when SystemSpec.build() makes it.
SystemSpec system(const std::string& where, const toml::node& value) {
    const toml::table& t = table(where, value);
    check_keys(where, t, kSystemKeys, {"V1", "V2"});
    SystemSpec s;
    s.V1 = potential(where + ".V1", *get(t, "V1"));
    s.V2 = potential(where + ".V2", *get(t, "V2"));
    if (const toml::node* c = get(t, "coupling")) s.coupling = coupling(where + ".coupling", *c);
    if (const toml::node* e = get(t, "eps")) s.eps = real(where + ".eps", *e, Bounds{-10.0, 10.0});
    const Bounds negative{std::nullopt, 0.0, false, true};
    if (const toml::node* q = get(t, "qw1")) s.qw1 = real(where + ".qw1", *q, negative);
    if (const toml::node* q = get(t, "qw2")) s.qw2 = real(where + ".qw2", *q, negative);
    if (const toml::node* g = get(t, "geometry")) s.geometry = text(where + ".geometry", *g, Keys{"none", "wall", "step"});
    const auto bad = [&](const std::string& msg) { fail(where + ": " + msg); };
    if (s.eps != 0 && s.coupling.empty()) bad("eps != 0 needs a coupling (e.g. hovering.Bilinear())");
    FlowSystem fs;
    fs.V1 = build(s.V1);
    fs.V2 = build(s.V2);
    for (const auto& [name, q, pot] : {std::tuple{"qw1", s.qw1, fs.V1}, std::tuple{"qw2", s.qw2, fs.V2}})
        if (!(std::fabs(q) < pot->q_limit()))
            bad(std::string(name) + " = " + py_float(q) + " lies outside the well of " + pot->name() + " (|" + name +
                "| < " + py_float(pot->q_limit()) + ")");
    fs.coupling.terms = s.coupling;
    fs.eps = s.eps;
    fs.qw1 = s.qw1;
    fs.qw2 = s.qw2;
    fs.geometry = s.geometry == "none" ? Geometry::None : s.geometry == "wall" ? Geometry::Wall : Geometry::Step;
    try {
        fs.validate();
    } catch (const std::invalid_argument& e) {
        bad(e.what());
    }
    return s;
}

void parse_flow_hovering_area(const std::string& where, const toml::table& root, SweepScene& s) {
    s.system = system(where + ".system", *get(root, "system"));
    s.h = 1.0;
    if (const toml::node* sec = get(root, "section")) {
        const toml::table& st = table(where + ".section", *sec);
        check_keys(where + ".section", st, {"h"}, {"h"});
        s.h = real(where + ".section.h", *get(st, "h"), Bounds{0.0, std::nullopt, true, false});
    }
    const double hw = build(s.system.V1)->V(s.system.qw1) + build(s.system.V2)->V(s.system.qw2);
    if (!(s.h > hw))
        fail(where + ".section.h = " + py_float(s.h) +
             " is out of range; allowed: above the step energy V1(qw1) + V2(qw2) + eps Vc(qw1, qw2) = " + py_g6(hw) +
             " (no tangency band below it)");
    if (const toml::node* in = get(root, "integrator")) {
        const std::string iw = where + ".integrator";
        const toml::table& it = table(iw, *in);
        check_keys(iw, it, kIntegratorKeys);
        const Bounds tol{1e-15, 1e-2};
        IntegratorSpec& g = s.integrator;
        g.rtol = it.contains("rtol") ? real(iw + ".rtol", *get(it, "rtol"), tol) : 1e-10;
        g.atol = it.contains("atol") ? real(iw + ".atol", *get(it, "atol"), tol) : g.rtol;
        g.stepper = it.contains("stepper") ? text(iw + ".stepper", *get(it, "stepper"), kSteppers) : "rk8pd";
        if (const toml::node* acc = get(it, "accuracy")) {
            Keys both;
            for (const char* k : {"atol", "rtol", "stepper"})  // sorted, as Python lists them
                if (it.contains(k)) both.push_back(k);
            if (!both.empty())
                fail(iw + ": 'accuracy' picks the stepper and tolerances itself; remove " + py_list(both) + " or 'accuracy'");
            g.accuracy = real(iw + ".accuracy", *acc, Bounds{1e-13, 1e-2});
        }
    }
    if (const toml::node* out = get(root, "outputs")) {
        const std::string ow = where + ".outputs";
        const toml::table& ot = table(ow, *out);
        check_keys(ow, ot, kOutputsKeys);
        if (const toml::node* rv = get(ot, "record")) {
            if (!rv->is_array()) fail(ow + ".record must be a list of names from ['regions'], got " + py_repr(*rv));
            for (const auto& r : *rv->as_array()) text(ow + ".record", r, Keys{"regions"});
            if (rv->as_array()->empty())  // every entry is 'regions' by now: only an empty list lacks it
                fail(ow + ".record = " + py_repr(*rv) + " lacks ['regions']: a flow_hovering_area figure is drawn from them");
        }
        if (ot.contains("trajectory_dt")) fail(ow + ".trajectory_dt is only used by scenes that record 'trajectory'");
    }
    if (s.system.geometry != "step")
        fail(where + ".system.geometry = " + py_str(s.system.geometry) +
             ": a flow_hovering_area scene draws the regions of the step; allowed: 'step'");
    s.eps = eps_list(where + ".eps", *get(root, "eps"), Bounds{-1.0, 1.0});
    if (const toml::node* mv = get(root, "models")) {
        if (!mv->is_array()) fail(where + ".models must be a list from ['onset', 'measured'], got " + py_repr(*mv));
        s.models.clear();
        for (const auto& m : *mv->as_array()) s.models.push_back(text(where + ".models", m, Keys{"onset", "measured"}));
    }
    s.n_steps = integer(where + ".n_steps", *get(root, "n_steps"), 1, 1'000'000);
    const toml::node* samples = get(root, "samples");
    s.samples = samples ? integer(where + ".samples", *samples, 16, 10'000'000) : 1000;
    const toml::node* seed = get(root, "seed");
    s.seed = seed ? static_cast<std::uint64_t>(integer(where + ".seed", *seed, 0, INT64_MAX)) : 0;
}

/// Replace the float literal that ends at `at` (toml++'s position just after it, in bytes or in
/// code points; toml++ quotes it without underscores) by inf; false if it is not found there.
bool literal_to_inf(std::string& doc, std::string_view literal, const toml::source_position& at) {
    std::size_t start = 0;
    for (std::size_t line = 1; line < at.line; ++line) {
        start = doc.find('\n', start);
        if (start == std::string::npos) return false;
        ++start;
    }
    const std::string_view line = std::string_view(doc).substr(start, doc.find('\n', start) - start);
    std::size_t by_code_point = 0;  // the byte after column - 1 code points
    for (std::size_t k = 1; k < at.column && by_code_point < line.size(); ++k) {
        ++by_code_point;
        while (by_code_point < line.size() && (static_cast<unsigned char>(line[by_code_point]) & 0xC0) == 0x80)
            ++by_code_point;
    }
    for (const std::size_t end : {static_cast<std::size_t>(at.column) - 1, by_code_point}) {
        if (end > line.size()) continue;
        // toml++ quotes the literal without its underscores.
        std::size_t i = end, j = literal.size();
        while (i > 0 && j > 0) {
            if (line[i - 1] == '_') --i;
            else if (line[i - 1] == literal[j - 1]) --i, --j;
            else break;
        }
        if (j == 0) {
            doc.replace(start + i, end - i, "inf");
            return true;
        }
    }
    return false;
}

/// The TOML document, or tomllib's "not valid TOML" (with toml++'s own detail). tomllib reads a float
/// literal beyond the double range as inf where toml++ refuses it (the one float error left once
/// toml++ has checked the literal's syntax): such literals become inf, sign kept, and the text is
/// read again.
toml::table parse_toml(std::string doc, const std::string& where) {
    // tomllib reads a byte-order mark as text (an invalid statement); toml++ would skip it.
    if (doc.compare(0, 3, "\xEF\xBB\xBF") == 0) fail(where + ": not valid TOML: Invalid statement (at line 1, column 1)");
    for (;;) {
        try {
            return toml::parse(doc);
        } catch (const toml::parse_error& e) {
            const std::string_view d = e.description();
            constexpr std::string_view head = "Error while parsing floating-point: '", tail = "' could not be interpreted as a value";
            if (d.size() > head.size() + tail.size() && d.substr(0, head.size()) == head &&
                d.substr(d.size() - tail.size()) == tail &&
                literal_to_inf(doc, d.substr(head.size(), d.size() - head.size() - tail.size()), e.source().begin))
                continue;
            fail(where + ": not valid TOML: " + std::string(d) + " (at line " + std::to_string(e.source().begin.line) +
                 ", column " + std::to_string(e.source().begin.column) + ")");
        }
    }
}

/// parse_scene for the sweep kinds: `origin` is the path as given (its name is `where` in the
/// messages, its stem the scene's name), `path` what SweepScene.path holds.
SweepScene parse(const std::string& doc, const std::string& origin, const std::string& path) {
    const std::string normalised = posix_path(origin);
    const std::string where = path_name(normalised);
    SweepScene s;
    s.path = path;
    s.name = path_stem(where);
    const toml::table root = parse_toml(doc, where);
    if (!root.contains("kind")) fail(where + ": missing required key 'kind'; allowed: " + py_choices(kKinds));
    s.kind = text(where + ".kind", *get(root, "kind"), kKinds);
    const bool truncated = s.kind == "hovering_area";
    if (!truncated && s.kind != "flow_hovering_area")
        fail(where + ".kind = " + py_str(s.kind) +
             ": hovering_sweep runs the sweep kinds 'hovering_area' and 'flow_hovering_area'; draw this scene with: "
             "python -m hovering scene " + normalised);
    if (truncated) check_keys(where, root, kHovKeys, {"kind", "output", "n_steps", "eps", "series"});
    else check_keys(where, root, kFlowHovKeys, {"kind", "output", "system", "n_steps", "eps"});
    s.title = root.contains("title") ? text(where + ".title", *get(root, "title")) : s.name;
    s.output = posix_path(text(where + ".output", *get(root, "output"), nullptr, kMaxPathChars));
    if (const toml::node* d = get(root, "dpi")) s.dpi = static_cast<int>(integer(where + ".dpi", *d, 30, 1200));
    double inches[2] = {13.0, 5.2};  // both sweep kinds' default figure (plot.figures._FIGSIZE)
    const bool sized = root.contains("figsize");
    if (const toml::node* f = get(root, "figsize")) {
        if (!f->is_array() || f->as_array()->size() != 2)
            fail(where + ".figsize must be [width, height] in inches, got " + py_repr(*f));
        for (std::size_t i = 0; i < 2; ++i)
            inches[i] = real(where + ".figsize[" + std::to_string(i) + "]", (*f->as_array())[i], Bounds{0.5, 60.0});
    }
    if (truncated) parse_hovering_area(where, root, s);
    else parse_flow_hovering_area(where, root, s);
    // _check_canvas: the figure python -m hovering would draw (hovering_sweep draws none).
    const double pixels = (s.dpi * inches[0]) * (s.dpi * inches[1]);
    if (pixels > kMaxCanvasPixels) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "%g x %g inches, a canvas of %.0f million pixels; allowed: at most %.0f million",
                      inches[0], inches[1], pixels / 1e6, kMaxCanvasPixels / 1e6);
        fail(where + ": dpi = " + std::to_string(s.dpi) + " and " + (sized ? "figsize" : "the default figure size") + " make a figure of " +
             buf + " (lower dpi or figsize)");
    }
    return s;
}

}  // namespace

std::pair<double, double> golden_family(double eps, double c, double tau0) {
    for (const auto& [name, v] : {std::pair{"eps", eps}, std::pair{"c", c}, std::pair{"tau0", tau0}})
        if (!std::isfinite(v)) fail(std::string(name) + " must be finite, got " + py_float(v));
    if (!(std::fabs(c) < std::fabs(tau0)))
        fail("c must satisfy |c| < |tau0| = " + py_float(std::fabs(tau0)) + ", got c = " + py_float(c));
    const double Omega0 = kOmegaG - 0.5 * c * eps;
    if (!(std::fabs(Omega0) <= 1e6))
        fail("eps = " + py_float(eps) + " and c = " + py_float(c) + " give Omega0 = Omega_G - c eps / 2 = " +
             py_g6(Omega0) + "; allowed: |Omega0| <= 1e6 (a larger rotation cannot be reduced mod 2 pi accurately)");
    // Python takes NumPy's arccos, which on AVX-512 machines can differ from the C library's by an ulp.
    return {Omega0, std::acos((c / tau0) * std::sin(0.5 * kOmegaG - 0.25 * c * eps))};
}

MapParams Series::at(double eps) const {
    MapParams m = map;
    if (golden) std::tie(m.Omega0, m.theta_w) = golden_family(eps, golden_c, m.tau0);
    return m;
}

SweepScene parse_sweep_scene(const std::string& text, const std::string& where) { return parse(text, where, ""); }

SweepScene load_sweep_scene(const std::string& path) {
    // load_scene's checks, on the path as pathlib has it.
    const std::string p = posix_path(path);
    const std::string name = path_name(p);
    struct stat st{};
    if (::stat(p.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) fail(p + ": not a regular file (a scene is a .toml file)");
    std::ifstream f(p, std::ios::binary);
    if (!f) {
        const int err = errno;  // what open() reported, as Python's OSError text
        throw std::runtime_error("[Errno " + std::to_string(err) + "] " + std::strerror(err) + ": " + py_str(p));
    }
    std::string raw(kMaxSceneBytes + 1, '\0');
    f.read(raw.data(), static_cast<std::streamsize>(raw.size()));
    raw.resize(static_cast<std::size_t>(f.gcount()));
    if (raw.size() > kMaxSceneBytes)
        fail(name + ": larger than " + std::to_string(kMaxSceneBytes) + " bytes; a scene file is a few hundred");
    if (const std::size_t bad = utf8_error(raw); bad != std::string::npos)
        fail(name + ": not UTF-8 text (TOML files are UTF-8): byte " + std::to_string(bad));
    return parse(raw, p, p);
}

}  // namespace hovering::scene
