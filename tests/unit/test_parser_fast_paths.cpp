// The classic reader's fast paths give exactly what the general code gives: plain decimals read
// while lexing (against std::from_chars and the reader's own integer rules), line and column from
// the sparse newline index (against a full scan), mapped and released source text, the tree's
// pools, gzip sized from its trailer.
#include <gtest/gtest.h>
#include <zlib.h>

#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "parser/field_value.h"
#include "parser/lexer.h"
#include "parser/load.h"
#include "parser/pool.h"
#include "support/tree_compare.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

// The general path: what parse_double returned before the fast path (sign, then from_chars).
bool reference_double(std::string_view w, double& out) {
    std::string_view body = w;
    bool negative = false;
    if (!body.empty() && (body.front() == '+' || body.front() == '-')) {
        negative = body.front() == '-';
        body.remove_prefix(1);
    }
    if (body.empty() ||
        !(std::isdigit(static_cast<unsigned char>(body.front())) || body.front() == '.'))
        return false;
    double v = 0;
    auto r = std::from_chars(body.data(), body.data() + body.size(), v, std::chars_format::general);
    if (r.ec != std::errc() || r.ptr != body.data() + body.size() || !std::isfinite(v))
        return false;
    out = negative ? -v : v;
    return true;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Random plain decimals: signs, leading zeros, 1 to 24 digits, points anywhere (or none).
std::vector<std::string> random_decimals(size_t n) {
    std::mt19937_64 rng(12345);
    std::vector<std::string> out;
    for (size_t i = 0; i < n; ++i) {
        std::string s;
        switch (rng() % 4) {
            case 0:
                s += '-';
                break;
            case 1:
                s += '+';
                break;
            default:
                break;
        }
        const int digits = 1 + static_cast<int>(rng() % 24);
        const int point = static_cast<int>(rng() % (digits + 2)) - 1;  // -1: none
        for (int d = 0; d < digits; ++d) {
            if (d == point) s += '.';
            s += static_cast<char>('0' + (rng() % 5 == 0 ? 0 : rng() % 10));
        }
        if (point == digits) s += '.';
        out.push_back(s);
    }
    return out;
}

TEST(ParserFastPaths, ParseDoubleIsBitIdenticalToFromChars) {
    std::vector<std::string> words = random_decimals(200000);
    for (const char* w : {"0",
                          "-0",
                          "1.",
                          ".5",
                          "+.5",
                          "-.5",
                          "9007199254740992",
                          "9007199254740993",
                          "0.1",
                          "0.3",
                          "1234567890123456789",
                          "12345678901234567890",
                          "0.0000000000000000000001",
                          "0.00000000000000000000001",
                          "4.35",
                          "2.675",
                          "1.7976931348623157",
                          ".",
                          "-",
                          "+",
                          "-.",
                          "1e5",
                          "1.5E-3",
                          "0x1F",
                          "1.2.3",
                          "",
                          "00000000000000000000000001.5"})
        words.push_back(w);
    size_t fast = 0;
    for (const std::string& w : words) {
        double expected = 0, got = 0;
        const bool ok = reference_double(w, expected);
        const bool hex = w.find('x') != std::string::npos;
        ASSERT_EQ(parse_double(w, got), ok || hex) << w;
        if (ok) {
            EXPECT_TRUE(same_bits(got, expected)) << w << ": " << got << " vs " << expected;
            ++fast;
        }
    }
    EXPECT_GT(fast, 150000u);
}

// Reads `words` as one MF field of `kind` and returns the values (or the error message).
struct Read {
    std::vector<double> values;
    std::string error;
    size_t warnings = 0;
};

Read read_mf(const std::string& words, ValueKind kind) {
    Read r;
    NodeTree tree;
    const std::string text = "[ " + words + " ]";
    Lexer lexer(text);
    Diagnostics diagnostics;
    ValueContext ctx{tree, lexer, &diagnostics, 0};
    FieldEntry entry;
    try {
        read_field_value(ctx, FieldType{kind, true}, entry);
        FieldView v = tree.view(entry);
        r.values.assign(v.numbers.begin(), v.numbers.end());
    } catch (const SyntaxError& e) {
        r.error = e.message + " @" + std::to_string(e.offset);
    }
    r.warnings = diagnostics.warning_count();
    return r;
}

TEST(ParserFastPaths, NumbersReadWhileLexingMatchTheWordParsers) {
    for (const std::string& w : random_decimals(20000)) {
        Read r = read_mf(w, ValueKind::Float);
        double expected = 0;
        if (reference_double(w, expected)) {
            ASSERT_EQ(r.error, "") << w;
            ASSERT_EQ(r.values.size(), 1u);
            EXPECT_TRUE(same_bits(r.values[0], expected)) << w;
        } else {
            EXPECT_NE(r.error, "") << w;
        }
    }
    // Integers: the fast path must keep the range, sign and spelling rules of parse_int32.
    for (const char* w :
         {"0", "-0", "+7", "007", "2147483647", "-2147483648", "2147483648", "-2147483649",
          "99999999999999999999", "0x7FFFFFFF", "0xFFFFFFFF", "-5", "3.0", "3.5", "1.", "-"}) {
        Read r = read_mf(w, ValueKind::Int32);
        int64_t i = 0;
        double d = 0;
        if (parse_int32(w, i)) {
            ASSERT_EQ(r.error, "") << w;
            EXPECT_TRUE(same_bits(r.values.at(0), static_cast<double>(i))) << w;
            EXPECT_EQ(r.warnings, 0u) << w;
        } else if (parse_double(w, d) && d == std::floor(d) && std::abs(d) <= 2147483647.0) {
            ASSERT_EQ(r.error, "") << w;
            EXPECT_EQ(r.values.at(0), d) << w;
            EXPECT_EQ(r.warnings, 1u) << w;  // integer written as a float
        } else {
            EXPECT_NE(r.error, "") << w;
        }
    }
}

TEST(ParserFastPaths, NextNumberKeepsTokenBoundaries) {
    const std::string text = "1.5{2}[-3]4e5,\"x\"-.5#c\n+7 .5. 0x1F -inf 12345678901234567890 x1 -";
    Lexer a(text), b(text);
    for (;;) {
        Decimal d;
        Token x = a.next(), y = b.next_number(d);
        ASSERT_EQ(int(x.kind), int(y.kind));
        ASSERT_EQ(x.offset, y.offset);
        ASSERT_EQ(x.length, y.length);
        if (d.plain) {
            double v = 0;
            ASSERT_TRUE(parse_double(a.text(x), v)) << a.text(x);
        }
        if (x.kind == TokenKind::End) break;
    }
}

// Line and column the obvious way: count every newline before the offset.
LineCol reference_line_col(std::string_view text, uint32_t offset) {
    uint32_t line = 1, start = 0;
    for (uint32_t i = 0; i < offset && i < text.size(); ++i)
        if (text[i] == '\n') {
            ++line;
            start = i + 1;
        }
    return {line, offset - start + 1};
}

std::string random_lines(size_t bytes, uint32_t seed) {
    std::mt19937 rng(seed);
    std::string text;
    while (text.size() < bytes) {
        const size_t len = rng() % 7 == 0 ? rng() % 3000 : rng() % 80;
        for (size_t i = 0; i < len; ++i) text += static_cast<char>('a' + rng() % 26);
        text += rng() % 5 == 0 ? "\r\n" : "\n";
        if (rng() % 50 == 0) text += "\n\n";
    }
    return text;
}

void check_lines(const SourceManager& sources, uint32_t file, std::string_view text,
                 uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<uint32_t> offsets = {0,
                                     1,
                                     static_cast<uint32_t>(text.size()),
                                     static_cast<uint32_t>(text.size() - 1),
                                     SourceFile::kLineBlock,
                                     SourceFile::kLineBlock - 1,
                                     SourceFile::kLineBlock + 1};
    for (int i = 0; i < 300; ++i)
        offsets.push_back(static_cast<uint32_t>(rng() % (text.size() + 1)));
    // Backwards first: the block index must grow correctly from any first request.
    std::sort(offsets.rbegin(), offsets.rend());
    for (uint32_t offset : offsets) {
        const LineCol want = reference_line_col(text, offset);
        const LineCol got = sources.line_col({file, offset});
        ASSERT_EQ(got.line, want.line) << offset;
        ASSERT_EQ(got.column, want.column) << offset;
        // The line's text, by number and by place, without its line break.
        size_t start = offset - (want.column - 1);
        size_t end = text.find('\n', start);
        std::string_view line = text.substr(
            start, end == std::string_view::npos ? std::string_view::npos : end - start);
        while (!line.empty() && (line.back() == '\r' || line.back() == '\n')) line.remove_suffix(1);
        ASSERT_EQ(sources.line_text(file, want.line), line) << offset;
        ASSERT_EQ(sources.line_text({file, offset}), line) << offset;
    }
    const uint32_t lines = reference_line_col(text, static_cast<uint32_t>(text.size())).line;
    EXPECT_EQ(sources.line_text(file, lines + 1), "");
    EXPECT_EQ(sources.line_text(file, 0), "");
}

TEST(ParserFastPaths, LineAndColumnFromTheSparseIndex) {
    for (uint32_t seed : {1u, 2u, 3u}) {
        const std::string text = random_lines(seed * 150000, seed);
        SourceManager sources;
        const uint32_t file = sources.add("a.wrl", text);
        check_lines(sources, file, text, seed);
    }
    SourceManager tiny;
    tiny.add("empty.wrl", std::string());
    EXPECT_EQ(tiny.line_col({0, 0}).line, 1u);
    EXPECT_EQ(tiny.line_text(0, 1), "");
}

// Per process (temp_path.h): two runs of this test at once (two checkouts' test commands) once
// shared these files, and one read the other's half-written or removed scene.
fs::path temp_path(const std::string& name) {
    return vr::test::temp_path("vrmlray_fast").string() + "_" + name;  // the name's extension last
}

TEST(ParserFastPaths, MappedTextReadsTheSameAfterItsPagesAreGivenBack) {
    const std::string text = random_lines(6 << 20, 7);
    const fs::path path = temp_path("mapped.txt");
    std::ofstream(path, std::ios::binary) << text;
    SourceManager sources;
    const uint32_t file = sources.add(path.string(), read_source_text(path, size_t(1) << 30));
    ASSERT_TRUE(sources.file(file).storage.mapped());
    ASSERT_EQ(sources.file(file).text, text);
    sources.release_before(file, static_cast<uint32_t>(text.size() - 100));
    EXPECT_EQ(sources.file(file).text, text);
    check_lines(sources, file, text, 9);
    EXPECT_EQ(sources.file(file).text, text);
    fs::remove(path);
}

TEST(ParserFastPaths, PoolsGrowIntoMappingsAndKeepTheirValues) {
    Pool<uint32_t> pool;
    for (uint32_t i = 0; i < 3'000'000; ++i) pool.push_back(i);  // heap, then a mapping that grows
    ASSERT_EQ(pool.size(), 3'000'000u);
    for (uint32_t i = 0; i < pool.size(); i += 997) ASSERT_EQ(pool[i], i);
    // Appending a part of the pool itself while it grows.
    pool.insert(pool.end(), pool.begin() + 10, pool.begin() + 2'000'000);
    ASSERT_EQ(pool.size(), 4'999'990u);
    EXPECT_EQ(pool[3'000'000], 10u);
    EXPECT_EQ(pool.back(), 1'999'999u);
    pool.push_back(pool[5]);
    EXPECT_EQ(pool.back(), 5u);
    Pool<uint32_t> copy = pool;
    Pool<uint32_t> moved = std::move(pool);
    EXPECT_TRUE(pool.empty());
    ASSERT_EQ(copy.size(), moved.size());
    EXPECT_TRUE(std::equal(copy.begin(), copy.end(), moved.begin()));
    copy.resize(3, 9);
    EXPECT_EQ(copy.size(), 3u);
    copy.resize(5, 9);
    EXPECT_EQ(copy[4], 9u);
    EXPECT_EQ(copy[2], 2u);
}

// A scene big enough to be mapped, with PROTO instances (read again from the released text),
// warnings and an error at its very end: plain and gzip-compressed read the same, messages
// included.
TEST(ParserFastPaths, LargeMappedAndGzipScenesReadAlike) {
    std::string text =
        "#VRML V2.0 utf8\n"
        "PROTO Atom [ field SFVec3f pos 0 0 0 field SFFloat r 1 ] {\n"
        "  Transform { translation IS pos children Shape { geometry Sphere { radius IS r } } "
        "}\n}\n";
    std::mt19937 rng(3);
    while (text.size() < (3u << 20)) {
        text += "Atom { pos " + std::to_string(rng() % 1000) + ".25 -" +
                std::to_string(rng() % 100) + ".5 " + std::to_string(rng() % 7) + " r 0." +
                std::to_string(rng() % 100) + " }\r\n";
        if (rng() % 5000 == 0) text += "Foo { }\n";
    }
    text += "Transform { translation 1 2 }\n";
    const fs::path plain = temp_path("big.wrl"), packed = temp_path("big.wrl.gz");
    std::ofstream(plain, std::ios::binary) << text;
    {
        gzFile gz = gzopen(packed.c_str(), "wb");
        gzwrite(gz, text.data(), static_cast<unsigned>(text.size()));
        gzclose(gz);
    }
    LoadedScene a = load_scene(plain), b = load_scene(packed),
                c = load_scene_text(text, plain.string());
    ASSERT_FALSE(a.ok());
    EXPECT_TRUE(a.sources.file(0).storage.mapped());
    EXPECT_FALSE(b.sources.file(0).storage.mapped());
    const std::string messages = a.diagnostics.format(a.sources);
    EXPECT_NE(messages.find("expected a number, found '}'"), std::string::npos) << messages;
    EXPECT_NE(messages.find("unknown node type 'Foo'"), std::string::npos) << messages;
    EXPECT_EQ(messages, c.diagnostics.format(c.sources));
    std::string gz_messages = b.diagnostics.format(b.sources);
    for (size_t p; (p = gz_messages.find(packed.string())) != std::string::npos;)
        gz_messages.replace(p, packed.string().size(), plain.string());
    EXPECT_EQ(messages, gz_messages);
    EXPECT_EQ(a.tree.nodes.size(), b.tree.nodes.size());
    EXPECT_EQ(a.tree.nodes.size(), c.tree.nodes.size());
    EXPECT_TRUE(std::equal(a.tree.numbers.begin(), a.tree.numbers.end(), b.tree.numbers.begin(),
                           b.tree.numbers.end()));
    fs::remove(plain);
    fs::remove(packed);
}

}  // namespace
}  // namespace vr
