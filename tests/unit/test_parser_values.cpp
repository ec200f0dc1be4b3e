// Field values of every type, in every spelling real files use.
#include <gtest/gtest.h>

#include <cmath>

#include "parser/field_value.h"
#include "parser/lexer.h"
#include "parser/load.h"

namespace vr {
namespace {

// Reads one value of `type` from `text` and returns the tree holding it.
struct Parsed {
    NodeTree tree;
    FieldEntry entry;
    std::string error;
    FieldView view() const { return tree.view(entry); }
};

Parsed parse(std::string_view text, FieldType type, bool xml = false) {
    Parsed p;
    Lexer lexer(text);
    Diagnostics diagnostics;
    ValueContext ctx{p.tree, lexer, &diagnostics, 0};
    ctx.xml = xml;
    try {
        read_field_value(ctx, type, p.entry);
        if (lexer.peek().kind != TokenKind::End) p.error = "trailing tokens";
    } catch (const SyntaxError& e) {
        p.error = e.message;
    }
    return p;
}

constexpr FieldType SF(ValueKind k) { return {k, false}; }
constexpr FieldType MF(ValueKind k) { return {k, true}; }

TEST(ParserValues, NumberSpellings) {
    struct Case {
        const char* text;
        double value;
    } cases[] = {{"1.", 1.0},      {".5", 0.5}, {"-0", 0.0},    {"1E+5", 1e5},       {"+.25", 0.25},
                 {"-1e-3", -1e-3}, {"3", 3.0},  {"0x10", 16.0}, {"1.5e300", 1.5e300}};
    for (const Case& c : cases) {
        Parsed p = parse(c.text, SF(ValueKind::Float));
        ASSERT_EQ(p.error, "") << c.text;
        EXPECT_EQ(p.view().numbers[0], c.value) << c.text;  // exact: from_chars rounds correctly
    }
    EXPECT_TRUE(std::signbit(parse("-0", SF(ValueKind::Float)).view().numbers[0]));
}

TEST(ParserValues, BadNumbersAreErrors) {
    for (const char* text : {"nan", "inf", "1e999", "1.2.3", "abc", "--1", "0x"}) {
        EXPECT_NE(parse(text, SF(ValueKind::Float)).error, "") << text;
    }
}

TEST(ParserValues, Int32IncludingHex) {
    EXPECT_EQ(parse("0xFF", SF(ValueKind::Int32)).view().numbers[0], 255.0);
    EXPECT_EQ(parse("-2147483648", SF(ValueKind::Int32)).view().numbers[0], -2147483648.0);
    EXPECT_EQ(parse("2147483647", SF(ValueKind::Int32)).view().numbers[0], 2147483647.0);
    EXPECT_NE(parse("2147483648", SF(ValueKind::Int32)).error, "");
    EXPECT_NE(parse("1.5", SF(ValueKind::Int32)).error, "");
    // An integral float in an integer field is accepted (exporters write "3.0"), with a warning.
    EXPECT_EQ(parse("3.0", SF(ValueKind::Int32)).view().numbers[0], 3.0);
}

TEST(ParserValues, Bool) {
    EXPECT_EQ(parse("TRUE", SF(ValueKind::Bool)).view().numbers[0], 1.0);
    EXPECT_EQ(parse("FALSE", SF(ValueKind::Bool)).view().numbers[0], 0.0);
    EXPECT_EQ(parse("true", SF(ValueKind::Bool), true).view().numbers[0], 1.0);
    EXPECT_NE(parse("1", SF(ValueKind::Bool)).error, "");
}

TEST(ParserValues, StringEscapes) {
    Parsed p = parse(R"("a\"b\\c")", SF(ValueKind::String));
    ASSERT_EQ(p.error, "");
    EXPECT_EQ(p.view().strings[0], "a\"b\\c");
    EXPECT_EQ(parse(R"("multi
line")",
                    SF(ValueKind::String))
                  .view()
                  .strings[0],
              "multi\nline");
    EXPECT_NE(parse(R"("open)", SF(ValueKind::String)).error, "");
}

TEST(ParserValues, MFWithAndWithoutBrackets) {
    EXPECT_EQ(parse("[1 2 3, 4 5 6,]", MF(ValueKind::Vec3f)).view().size(), 2u);  // trailing comma
    EXPECT_EQ(parse("1 2 3", MF(ValueKind::Vec3f)).view().size(), 1u);
    EXPECT_EQ(parse("[]", MF(ValueKind::Vec3f)).view().size(), 0u);
    EXPECT_EQ(parse(R"(["a" "b"])", MF(ValueKind::String)).view().strings.size(), 2u);
    EXPECT_EQ(parse(R"("a")", MF(ValueKind::String)).view().strings.size(), 1u);
    EXPECT_EQ(parse("[0,1,2,-1,2,3,0,-1]", MF(ValueKind::Int32)).view().size(), 8u);
    // A value cut short is an error, not a silently shorter list.
    EXPECT_NE(parse("[1 2 3 4]", MF(ValueKind::Vec3f)).error, "");
    EXPECT_NE(parse("[1 2 3", MF(ValueKind::Vec3f)).error, "");
}

TEST(ParserValues, XmlAttributesListWithoutBrackets) {
    EXPECT_EQ(parse("1 2 3 4 5 6", MF(ValueKind::Vec3f), true).view().size(), 2u);
    EXPECT_EQ(parse(R"("a" "b" "c")", MF(ValueKind::String), true).view().size(), 3u);
}

TEST(ParserValues, RotationAxisIsNormalised) {
    Parsed p = parse("0 0 2 1.5", SF(ValueKind::Rotation));
    ASSERT_EQ(p.error, "");
    auto r = p.view().numbers;
    EXPECT_DOUBLE_EQ(r[2], 1.0);
    EXPECT_DOUBLE_EQ(r[3], 1.5);
}

TEST(ParserValues, AllVectorKinds) {
    EXPECT_EQ(parse("1 2", SF(ValueKind::Vec2f)).view().numbers.size(), 2u);
    EXPECT_EQ(parse("1 2 3 4", SF(ValueKind::Vec4f)).view().numbers.size(), 4u);
    EXPECT_EQ(parse("1 2 3", SF(ValueKind::Vec3d)).view().numbers.size(), 3u);
    EXPECT_EQ(parse("1 0 0 1", SF(ValueKind::ColorRGBA)).view().numbers.size(), 4u);
    EXPECT_EQ(parse("1 0 0 0 1 0 0 0 1", SF(ValueKind::Matrix3f)).view().numbers.size(), 9u);
    EXPECT_EQ(
        parse("1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1", SF(ValueKind::Matrix4d)).view().numbers.size(),
        16u);
    EXPECT_EQ(parse("12.5", SF(ValueKind::Time)).view().numbers[0], 12.5);
    EXPECT_EQ(parse("0.25", SF(ValueKind::Double)).view().numbers[0], 0.25);
}

TEST(ParserValues, Image) {
    Parsed p = parse("2 1 3 0xFF0000 0x00FF00", SF(ValueKind::Image));
    ASSERT_EQ(p.error, "");
    auto n = p.view().numbers;
    ASSERT_EQ(n.size(), 5u);
    EXPECT_EQ(n[3], double(0xFF0000));
    EXPECT_NE(parse("2 2 3 0xFF0000", SF(ValueKind::Image)).error, "");  // too few pixels
    // A claimed size far beyond the limit is refused before anything is allocated.
    EXPECT_NE(parse("100000 100000 3 0", SF(ValueKind::Image)).error, "");
}

TEST(ParserValues, NodeKindsTakeOnlyNullAndEmpty) {
    EXPECT_EQ(parse("NULL", SF(ValueKind::Node)).view().nodes[0], kNullNode);
    EXPECT_EQ(parse("[]", MF(ValueKind::Node)).view().nodes.size(), 0u);
}

// castle-engine-demo-models/x3d/warnings/backslashes.x3dv: "\\b" and Windows paths lose their
// backslash silently, so the author's text changes without a word.
TEST(ParserValues, BackslashBeforeAnOrdinaryCharacterWarnsOnceAndIsDropped) {
    const LoadedScene loaded = load_scene_text(
        "#VRML V2.0 utf8\nWorldInfo { info [\"ok \\\" and \\\\\" \"bad \\blah\" \"C:\\x\\y\"] }\n",
        "t.wrl");
    ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    ASSERT_EQ(loaded.diagnostics.warning_count(), 1u) << loaded.diagnostics.format(loaded.sources);
    const Diagnostic& d = loaded.diagnostics.all()[0];
    EXPECT_NE(d.message.find("backslash before 'b'"), std::string::npos) << d.message;
    EXPECT_EQ(d.count, 2u);  // the second string's "\\x" is the same cause
    // The place is the backslash: "bad \blah" starts after 'info [' and the first string.
    const std::string_view text = loaded.sources.file(0).text;
    EXPECT_EQ(text.substr(d.loc.offset, 2), "\\b");
}

}  // namespace
}  // namespace vr
