#include "parser/field_value.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>

namespace vr {

bool parse_double(std::string_view w, double& out) {
    if (w.empty()) return false;
    std::string_view body = w;
    bool negative = false;
    if (body.front() == '+' || body.front() == '-') {
        negative = body.front() == '-';
        body.remove_prefix(1);
    }
    // Plain decimals, the bulk of every scene, exactly as from_chars below would read them.
    const auto* first = reinterpret_cast<const unsigned char*>(w.data());
    Decimal d;
    if (read_decimal(first, first + w.size(), d) == first + w.size() && d.to_double(out))
        return true;
    if (body.size() > 2 && body[0] == '0' && (body[1] == 'x' || body[1] == 'X')) {
        int64_t v;
        if (!parse_int32(w, v)) return false;
        out = static_cast<double>(v);
        return true;
    }
    if (body.empty() ||
        !(std::isdigit(static_cast<unsigned char>(body.front())) || body.front() == '.'))
        return false;
    double v = 0;
    auto r = std::from_chars(body.data(), body.data() + body.size(), v, std::chars_format::general);
    if (r.ec != std::errc() || r.ptr != body.data() + body.size()) return false;
    if (!std::isfinite(v)) return false;
    out = negative ? -v : v;
    return true;
}

bool parse_int32(std::string_view w, int64_t& out) {
    if (w.empty()) return false;
    bool negative = false;
    std::string_view body = w;
    if (body.front() == '+' || body.front() == '-') {
        negative = body.front() == '-';
        body.remove_prefix(1);
    }
    int base = 10;
    if (body.size() > 2 && body[0] == '0' && (body[1] == 'x' || body[1] == 'X')) {
        base = 16;
        body.remove_prefix(2);
    }
    if (body.empty()) return false;
    uint64_t v = 0;
    auto r = std::from_chars(body.data(), body.data() + body.size(), v, base);
    if (r.ec != std::errc() || r.ptr != body.data() + body.size()) return false;
    if (base == 16 ? v > 0xFFFFFFFFull : v > 0x80000000ull) return false;
    int64_t s = negative ? -static_cast<int64_t>(v) : static_cast<int64_t>(v);
    if (base == 10 && s > INT32_MAX) return false;
    out = s;
    return true;
}

bool normalise_rotation(double* r) {
    double len2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    if (len2 == 0.0) return r[3] == 0.0;  // a zero axis only makes sense with a zero angle
    // Unit to within double rounding: left as written, so that reading a written file again changes
    // nothing.
    if (std::abs(len2 - 1.0) <= 8.0 * std::numeric_limits<double>::epsilon()) return true;
    double inv = 1.0 / std::sqrt(len2);
    r[0] *= inv;
    r[1] *= inv;
    r[2] *= inv;
    // Any other axis has one direction, which every browser takes: normalised silently, so that
    // --strict stays usable on Jmol's exports (their bond axes are unnormalised, of lengths 0.076
    // to 10 in ../shared/corpus/molecular/jmol).
    return true;
}

namespace {

[[noreturn]] void fail(const Token& t, std::string message) {
    throw SyntaxError{t.offset, std::move(message)};
}

double read_number(ValueContext& ctx, ValueKind kind) {
    Decimal d;
    Token t = kind == ValueKind::Bool ? ctx.lexer.next() : ctx.lexer.next_number(d);
    // The common spellings, converted exactly as the general code below would.
    if (kind != ValueKind::Int32) {
        double v;
        if (d.to_double(v)) return v;
    } else if (d.plain && d.fraction < 0 &&
               d.digits <= (d.negative ? 0x80000000ull : 0x7fffffffull)) {
        const int64_t v = static_cast<int64_t>(d.digits);
        return static_cast<double>(d.negative ? -v : v);
    }
    if (t.kind != TokenKind::Word) fail(t, "expected a number, found " + ctx.lexer.describe(t));
    std::string_view w = ctx.lexer.text(t);
    if (kind == ValueKind::Int32) {
        int64_t v;
        if (parse_int32(w, v)) return static_cast<double>(v);
        double d;
        if (parse_double(w, d) && d == std::floor(d) && std::abs(d) <= 2147483647.0) {
            if (ctx.diagnostics)
                ctx.diagnostics->warning({ctx.file, t.offset},
                                         "integer written as a float: " + std::string(w),
                                         "int-as-float");
            return d;
        }
        fail(t, "expected an integer, found " + ctx.lexer.describe(t));
    }
    if (kind == ValueKind::Bool) {
        if (w == "TRUE" || (ctx.xml && w == "true")) return 1.0;
        if (w == "FALSE" || (ctx.xml && w == "false")) return 0.0;
        if (w == "true" || w == "false") {
            if (ctx.diagnostics)
                ctx.diagnostics->warning({ctx.file, t.offset},
                                         "lower-case boolean '" + std::string(w) + "'",
                                         "lower-case-bool");
            return w == "true" ? 1.0 : 0.0;
        }
        fail(t, "expected TRUE or FALSE, found " + ctx.lexer.describe(t));
    }
    double v;
    if (parse_double(w, v)) return v;
    if (w == "nan" || w == "NaN" || w == "inf" || w == "-inf" || w == "INF")
        fail(t, "number is not finite: " + std::string(w));
    fail(t, "expected a number, found " + ctx.lexer.describe(t));
}

void check_size(ValueContext& ctx, size_t count, const Token& t) {
    if (count > ctx.max_values)
        fail(t, "field holds more than " + std::to_string(ctx.max_values) + " values (limit)");
}

// One SFImage: width height components, then width*height pixel integers.
void read_image(ValueContext& ctx, const Token& at) {
    auto& nums = ctx.tree.numbers;
    double w = read_number(ctx, ValueKind::Int32);
    double h = read_number(ctx, ValueKind::Int32);
    double c = read_number(ctx, ValueKind::Int32);
    if (w < 0 || h < 0 || c < 0 || c > 4) fail(at, "SFImage size or component count out of range");
    double pixels = w * h;
    check_size(ctx, static_cast<size_t>(pixels), at);
    nums.push_back(w);
    nums.push_back(h);
    nums.push_back(c);
    for (size_t i = 0; i < static_cast<size_t>(pixels); ++i) {
        Token t = ctx.lexer.peek();
        if (t.kind != TokenKind::Word)
            fail(t, "SFImage has fewer pixels than its size " + std::to_string(int64_t(w)) + "x" +
                        std::to_string(int64_t(h)) + " says");
        ctx.lexer.next();
        int64_t v;
        std::string_view word = ctx.lexer.text(t);
        if (!parse_int32(word, v))
            fail(t, "expected a pixel value, found " + ctx.lexer.describe(t));
        nums.push_back(static_cast<double>(v < 0 ? v + 4294967296LL : v));
    }
}

void read_string(ValueContext& ctx) {
    Token t = ctx.lexer.next();
    if (t.kind == TokenKind::String) {
        const std::string_view quoted = ctx.lexer.text(t);
        // VRML97 5.9 / X3D classic: only \" and \\ are escapes; any other backslash is dropped
        // (as the readers of browsers drop it), which changes what the author wrote.
        for (size_t i = 1; ctx.diagnostics && i + 2 < quoted.size(); ++i) {
            if (quoted[i] != '\\') continue;
            if (quoted[i + 1] != '"' && quoted[i + 1] != '\\') {
                ctx.diagnostics->warning(
                    {ctx.file, t.offset + i},
                    std::string("a backslash before '") + quoted[i + 1] +
                        "' is not an escape (only \\\" and \\\\ are); it is dropped",
                    "string-escape");
                break;
            }
            ++i;
        }
        ctx.tree.strings.push_back(Lexer::unescape(quoted));
        return;
    }
    if (t.kind == TokenKind::BadString) fail(t, "string is not closed before the end of the file");
    fail(t, "expected a string, found " + ctx.lexer.describe(t));
}

void read_single(ValueContext& ctx, ValueKind kind, const Token& at) {
    if (kind == ValueKind::String) return read_string(ctx);
    if (kind == ValueKind::Image) return read_image(ctx, at);
    int n = components(kind);
    size_t start = ctx.tree.numbers.size();
    for (int i = 0; i < n; ++i) ctx.tree.numbers.push_back(read_number(ctx, kind));
    if (kind == ValueKind::Rotation) {
        double* r = ctx.tree.numbers.data() + start;
        if (!normalise_rotation(r) && ctx.diagnostics)
            ctx.diagnostics->warning({ctx.file, at.offset},
                                     "rotation axis is not unit length; normalised",
                                     "rotation-axis");
    }
}

}  // namespace

void read_field_value(ValueContext& ctx, FieldType type, FieldEntry& entry) {
    NodeTree& tree = ctx.tree;
    entry.type = type;
    Token first = ctx.lexer.peek();
    entry.loc = {ctx.file, first.offset};
    if (type.kind == ValueKind::Node) {
        entry.begin = static_cast<uint32_t>(tree.node_refs.size());
        entry.count = 0;
        Token t = ctx.lexer.next();
        if (!type.multi && t.kind == TokenKind::Word && ctx.lexer.text(t) == "NULL") {
            tree.node_refs.push_back(kNullNode);
            entry.count = 1;
            return;
        }
        if (type.multi && t.kind == TokenKind::LBracket &&
            ctx.lexer.peek().kind == TokenKind::RBracket) {
            ctx.lexer.next();
            return;
        }
        fail(t, "expected a node value");
    }
    const bool strings = type.kind == ValueKind::String;
    entry.begin = static_cast<uint32_t>(strings ? tree.strings.size() : tree.numbers.size());
    auto pool_size = [&] { return strings ? tree.strings.size() : tree.numbers.size(); };
    if (!type.multi) {
        read_single(ctx, type.kind, first);
    } else if (first.kind == TokenKind::LBracket) {
        ctx.lexer.next();
        const int n = components(type.kind);
        for (;;) {
            Token t = ctx.lexer.peek();
            if (t.kind == TokenKind::RBracket) {
                ctx.lexer.next();
                break;
            }
            if (t.kind == TokenKind::End)
                fail(first, "'[' is not closed before the end of the file");
            if (n == 1 && !strings) {
                // Fast path for MFFloat/MFInt32 and friends, the bulk of large files.
                ctx.tree.numbers.push_back(read_number(ctx, type.kind));
            } else {
                read_single(ctx, type.kind, t);
            }
            check_size(ctx, pool_size() - entry.begin, first);
        }
    } else if (!ctx.xml) {
        read_single(ctx, type.kind, first);
        // Several numbers without brackets (`fieldOfView -1 -1 1 1`, as X3D 3 files write
        // OrthoViewpoint's): no field name starts like a number, so the run can only be this
        // value. Read whole, with one warning a file.
        auto number_next = [&] {
            const Token& t = ctx.lexer.peek();
            const char c = t.kind == TokenKind::Word ? ctx.lexer.text(t).front() : 'x';
            return std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.';
        };
        if (!strings && type.kind != ValueKind::Image && number_next()) {
            while (number_next()) {
                read_single(ctx, type.kind, ctx.lexer.peek());
                check_size(ctx, pool_size() - entry.begin, first);
            }
            if (ctx.diagnostics)
                ctx.diagnostics->warning({ctx.file, first.offset},
                                         "several values of a multiple-valued field without "
                                         "brackets; read as one list",
                                         "mf-without-brackets");
        }
    } else {
        // X3D XML attributes list MF values without brackets.
        while (ctx.lexer.peek().kind != TokenKind::End) {
            read_single(ctx, type.kind, ctx.lexer.peek());
            check_size(ctx, pool_size() - entry.begin, first);
        }
    }
    entry.count = static_cast<uint32_t>(pool_size() - entry.begin);
}

}  // namespace vr
