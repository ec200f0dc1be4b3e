// Text: UTF-8, the nonzero fill of outlines with holes, glyph placement against FreeType's own
// metrics, FontStyle justification, spacing, length and maxExtent by hand-computed offsets, the
// font fallback, VRML 1.0 AsciiText, and corpus files whose only geometry is text.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "corpus.h"
#include "flatten/flatten.h"
#include "geometry/fill.h"
#include "geometry/font.h"
#include "geometry/text.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/render.h"
#include "scene/build.h"

#if __has_include(<ft2build.h>)
#include <ft2build.h>
#include FT_FREETYPE_H
#define VR_TEST_FREETYPE 1
#endif

namespace vr {
namespace {

namespace fs = std::filesystem;

TEST(TextUtf8, DecodesEveryLengthAndReplacesMalformedBytes) {
    EXPECT_EQ(decode_utf8("a\xC3\xA9\xE2\x82\xAC\xF0\x9F\x98\x80"), U"a\u00E9\u20AC\U0001F600");
    // A lone continuation byte, a truncated sequence, an overlong '/', a surrogate: one U+FFFD
    // each, and decoding goes on with the next byte.
    EXPECT_EQ(decode_utf8("\x80x"), U"\uFFFDx");
    EXPECT_EQ(decode_utf8("\xE2\x82"), U"\uFFFD\uFFFD");
    EXPECT_EQ(decode_utf8("\xC0\xAF"), U"\uFFFD\uFFFD");
    EXPECT_EQ(decode_utf8("\xED\xA0\x80"), U"\uFFFD\uFFFD\uFFFD");
}

double area(const FlatTriangles& t) {
    double sum = 0.0;
    for (size_t i = 0; i + 2 < t.triangles.size(); i += 3) {
        const Vec2 a = t.points[t.triangles[i]], b = t.points[t.triangles[i + 1]],
                   c = t.points[t.triangles[i + 2]];
        const double twice = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        EXPECT_GT(twice, 0.0) << "triangle " << i / 3 << " is not counter-clockwise";
        sum += 0.5 * twice;
    }
    return sum;
}

bool covers(const FlatTriangles& t, Vec2 p) {
    for (size_t i = 0; i + 2 < t.triangles.size(); i += 3) {
        const Vec2 v[3] = {t.points[t.triangles[i]], t.points[t.triangles[i + 1]],
                           t.points[t.triangles[i + 2]]};
        bool inside = true;
        for (int k = 0; k < 3; ++k) {
            const Vec2 a = v[k], b = v[(k + 1) % 3];
            inside = inside && (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x) >= 0.0;
        }
        if (inside) return true;
    }
    return false;
}

// The areas below are sums of products of small integers and halves: exact in doubles, so the
// fill must match them to rounding (1e-12).
TEST(TextFill, SquareWithAHoleLeavesTheHoleEmpty) {
    const std::vector<std::vector<Vec2>> ring = {{{0, 0}, {4, 0}, {4, 4}, {0, 4}},
                                                 {{1, 1}, {1, 3}, {3, 3}, {3, 1}}};  // clockwise
    const FlatTriangles t = fill_nonzero(ring);
    EXPECT_NEAR(area(t), 16.0 - 4.0, 1e-12);
    EXPECT_FALSE(covers(t, {2.0, 2.0}));
    EXPECT_TRUE(covers(t, {0.5, 2.0}));
}

TEST(TextFill, OverlapsCountOnceAndCrossingEdgesAreSplit) {
    // Two squares of the same orientation overlapping in a unit square: nonzero winding fills the
    // union (4 + 4 - 1).
    const FlatTriangles both =
        fill_nonzero({{{0, 0}, {2, 0}, {2, 2}, {0, 2}}, {{1, 1}, {3, 1}, {3, 3}, {1, 3}}});
    EXPECT_NEAR(area(both), 7.0, 1e-12);
    // A bow tie crosses itself at (1, 1): two triangles of area 1, nothing between them.
    const FlatTriangles bow = fill_nonzero({{{0, 0}, {2, 2}, {2, 0}, {0, 2}}});
    EXPECT_NEAR(area(bow), 2.0, 1e-12);
    EXPECT_FALSE(covers(bow, {1.0, 0.2}));
    EXPECT_TRUE(covers(bow, {0.2, 1.0}));
}

sg::Text text_of(std::vector<std::string> strings, std::vector<std::string> family = {"SANS"}) {
    sg::Text t;
    t.strings = std::move(strings);
    t.font.family = std::move(family);
    t.font.size = 2.0;
    t.font.spacing = 1.5;
    return t;
}

std::shared_ptr<const Font> sans() {
    const FontChoice c = find_font(text_of({}).font);
    EXPECT_TRUE(c.problem.empty()) << c.problem;
    return c.font;
}

#define VR_NEED_FONTS()                                                              \
    if (!fonts_available()) GTEST_SKIP() << "built without FreeType and fontconfig"; \
    const std::shared_ptr<const Font> font = sans();                                 \
    ASSERT_NE(font, nullptr)

#ifdef VR_TEST_FREETYPE
// FreeType's advance of a character in em units, read here without vrmlray's font code.
struct FreeTypeMetrics {
    FT_Library library = nullptr;
    FT_Face face = nullptr;
    explicit FreeTypeMetrics(const std::string& file) {
        EXPECT_EQ(FT_Init_FreeType(&library), 0);
        EXPECT_EQ(FT_New_Face(library, file.c_str(), 0, &face), 0) << file;
    }
    ~FreeTypeMetrics() {
        if (face) FT_Done_Face(face);
        if (library) FT_Done_FreeType(library);
    }
    double advance(char32_t c) const {
        EXPECT_EQ(FT_Load_Char(face, c, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING), 0);
        return double(face->glyph->advance.x) / face->units_per_EM;
    }
    double kerning(char32_t left, char32_t right) const {
        FT_Vector k{};
        EXPECT_EQ(FT_Get_Kerning(face, FT_Get_Char_Index(face, left),
                                 FT_Get_Char_Index(face, right), FT_KERNING_UNSCALED, &k),
                  0);
        return double(k.x) / face->units_per_EM;
    }
};

TEST(TextLayout, GlyphsAdvanceByFreeTypesAdvancesAndKerning) {
    VR_NEED_FONTS();
    const FreeTypeMetrics ft(font->file());
    // "AV" and "To" are kerned pairs in DejaVu Sans (its kern table): each pair's distance is the
    // first glyph's advance plus the pair's kerning, as a browser lays text out.
    const sg::Text text = text_of({"AVTo\u00E9"});
    const TextLayout layout = layout_text(text, *font);
    ASSERT_EQ(layout.glyphs.size(), 5u);
    double pen = 0.0;
    for (size_t k = 0; k < layout.glyphs.size(); ++k) {
        const PlacedGlyph& g = layout.glyphs[k];
        // The same sums in the same order: equal to rounding.
        EXPECT_NEAR(g.origin.x, pen, 1e-12) << char(g.code);
        EXPECT_EQ(g.origin.y, 0.0);  // the first baseline at y = 0 (minor FIRST)
        EXPECT_EQ(g.scale, Vec2(2.0));
        const double kern =
            k + 1 < layout.glyphs.size() ? ft.kerning(g.code, layout.glyphs[k + 1].code) : 0.0;
        pen += (ft.advance(g.code) + kern) * text.font.size;
    }
}

TEST(TextLayout, KernedPairIsCloserThanTheSumOfAdvances) {
    VR_NEED_FONTS();
    const FreeTypeMetrics ft(font->file());
    // DejaVu Sans pulls V under A's arm (-131/2048 em); the layout's V starts that much earlier.
    ASSERT_LT(ft.kerning(U'A', U'V'), 0.0) << "the matched sans font has no AV kerning";
    for (bool ltr : {true, false}) {
        sg::Text text = text_of({"AV"});
        text.font.left_to_right = ltr;
        const TextLayout layout = layout_text(text, *font);
        ASSERT_EQ(layout.glyphs.size(), 2u);
        // Read right to left, "AV" shows as VA: the pair kerned is then (V, A).
        const PlacedGlyph& left = ltr ? layout.glyphs[0] : layout.glyphs[1];
        const PlacedGlyph& right = ltr ? layout.glyphs[1] : layout.glyphs[0];
        const double want = (ft.advance(left.code) + ft.kerning(left.code, right.code)) * 2.0;
        EXPECT_NEAR(right.origin.x - left.origin.x, want, 1e-12) << "left to right " << ltr;
    }
}

TEST(TextLayout, JustifyAndSpacingPlaceLinesByHandComputedOffsets) {
    VR_NEED_FONTS();
    const FreeTypeMetrics ft(font->file());
    const double size = 2.0;
    const double ab = (ft.advance('a') + ft.advance('b')) * size;
    const double abc = ab + ft.advance('c') * size;
    sg::Text text = text_of({"ab", "abc"});
    auto first_x = [&](size_t line) {
        const TextLayout l = layout_text(text, *font);
        for (const PlacedGlyph& g : l.glyphs)
            if (g.line == line) return g.origin;
        return Vec2(NAN);
    };
    // BEGIN: each line starts at x = 0; the second baseline is spacing * size lower.
    EXPECT_NEAR(first_x(1).x, 0.0, 1e-12);
    EXPECT_NEAR(first_x(1).y, -1.5 * size, 1e-12);
    text.font.major = sg::Justify::Middle;
    EXPECT_NEAR(first_x(0).x, -ab / 2, 1e-12);
    EXPECT_NEAR(first_x(1).x, -abc / 2, 1e-12);
    text.font.major = sg::Justify::End;
    EXPECT_NEAR(first_x(1).x, -abc, 1e-12);
    // Right to left: the first character is rightmost, ending at x = 0 for BEGIN.
    text.font.major = sg::Justify::Begin;
    text.font.left_to_right = false;
    EXPECT_NEAR(first_x(0).x, -ft.advance('a') * size, 1e-12);
    text.font.left_to_right = true;
    // Bottom to top: the second line above the first.
    text.font.top_to_bottom = false;
    EXPECT_NEAR(first_x(1).y, 1.5 * size, 1e-12);
    text.font.top_to_bottom = true;
    // Minor BEGIN: the first line's ascender at y = 0; END: the last line's descender there.
    const double asc = font->ascender() * size, desc = font->descender() * size;
    text.font.minor = sg::Justify::Begin;
    EXPECT_NEAR(first_x(0).y, -asc, 1e-12);
    text.font.minor = sg::Justify::End;
    EXPECT_NEAR(first_x(1).y, -desc, 1e-12);
    text.font.minor = sg::Justify::Middle;
    EXPECT_NEAR(first_x(0).y, -0.5 * (asc + (-1.5 * size + desc)), 1e-12);
}

TEST(TextLayout, LengthStretchesALineAndMaxExtentCompressesTheLongest) {
    VR_NEED_FONTS();
    const FreeTypeMetrics ft(font->file());
    const double size = 2.0, ab = (ft.advance('a') + ft.advance('b')) * size;
    sg::Text text = text_of({"ab", "abcd"});
    text.length = {10.0};  // the first line only; 0 or missing: natural length
    TextLayout l = layout_text(text, *font);
    EXPECT_NEAR(l.glyphs[1].origin.x, ft.advance('a') * size * 10.0 / ab, 1e-12);
    EXPECT_NEAR(l.glyphs[0].scale.x, size * 10.0 / ab, 1e-12);
    EXPECT_EQ(l.glyphs[2].scale.x, size);
    // maxExtent 4 below the 10 of the first line: every line shrinks by 4/10.
    text.max_extent = 4.0;
    l = layout_text(text, *font);
    EXPECT_NEAR(l.glyphs[1].origin.x, ft.advance('a') * size * 4.0 / ab, 1e-12);
    EXPECT_NEAR(l.glyphs[2].scale.x, size * 0.4, 1e-12);
}
#endif

// Shoelace area of the contours, signed by the font's winding (TrueType outer contours run
// clockwise): for glyphs without overlapping contours, |sum| is the filled area.
double outline_area(const GlyphShape& g) {
    double sum = 0.0;
    for (const auto& c : g.contours)
        for (size_t i = 0; i < c.size(); ++i) {
            const Vec2 a = c[i], b = c[(i + 1) % c.size()];
            sum += 0.5 * (a.x * b.y - b.x * a.y);
        }
    return std::fabs(sum);
}

TEST(TextMesh, GlyphsWithHolesCoverTheirOutlineAreaAndLeaveTheCounterOpen) {
    VR_NEED_FONTS();
    Diagnostics diagnostics;
    sg::Origin origin;
    for (const char* s : {"o", "B", "8", "e"}) {
        SCOPED_TRACE(s);
        NodeReport report(diagnostics, origin);
        const sg::Text text = text_of({s});
        const TriMesh mesh = text_mesh(text, false, report);
        ASSERT_GT(mesh.triangle_count(), 0u);
        // Both sides from the same flattened contours (1e-3 em): equal to rounding.
        const double expected = outline_area(font->glyph(U'\0' + s[0], 1e-3)) * 4.0;
        EXPECT_NEAR(mesh.area(), expected, 1e-9 * expected);
        for (const Vec3& p : mesh.positions) EXPECT_EQ(p.z, 0.0);
        EXPECT_FALSE(mesh.solid);  // Text is seen from both sides unless X3D says solid TRUE
    }
    // The counter of an 'o': its middle (at x-height/2) must not be filled.
    const GlyphShape o = font->glyph(U'o', 1e-3);
    Vec2 lo(1e9), hi(-1e9);
    for (const auto& c : o.contours)
        for (const Vec2& p : c) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const FlatTriangles filled = fill_nonzero(o.contours);
    EXPECT_FALSE(covers(filled, 0.5 * (lo + hi)));
    EXPECT_TRUE(covers(filled, Vec2(lo.x + 0.02, 0.5 * (lo.y + hi.y))));  // the bowl's left side
}

struct Built {
    LoadedScene loaded;
    Diagnostics diagnostics;
    Scene scene;
};

Built build(const std::string& text, const std::string& name = "test.wrl") {
    Built b;
    b.loaded = load_scene_text(text, name);
    EXPECT_TRUE(b.loaded.ok()) << b.loaded.diagnostics.format(b.loaded.sources);
    b.scene = build_scene(b.loaded, b.diagnostics);
    return b;
}

const sg::Text* first_text(const Scene& scene) {
    for (const sg::Geometry& g : scene.geometries)
        if (const auto* t = std::get_if<std::unique_ptr<sg::Text>>(&g.shape)) return t->get();
    return nullptr;
}

TEST(TextFonts, AMissingFamilyFallsBackWithOneWarningAndAListTakesTheFirstFound) {
    if (!fonts_available()) GTEST_SKIP() << "built without FreeType and fontconfig";
    Built b = build(R"(#VRML V2.0 utf8
        Shape { geometry Text { string "x" fontStyle FontStyle { family "NoSuchFamilyXyz" } } }
        Shape { geometry Text { string "y" fontStyle FontStyle { family "NoSuchFamilyXyz" } } }
        Shape { geometry Text { string "z" fontStyle FontStyle { family ["NoSuchFamilyXyz" "TYPEWRITER"] } } })");
    FlattenOptions fo;
    FlattenStats stats;
    const FlatScene flat = flatten_scene(b.scene, fo, b.diagnostics, stats);
    EXPECT_EQ(flat.meshes.size(), 3u);  // the fallback font draws them all
    size_t fallbacks = 0;
    for (const Diagnostic& d : b.diagnostics.all())
        if (d.message.find("'NoSuchFamilyXyz' not found") != std::string::npos) {
            ++fallbacks;
            EXPECT_EQ(d.count, 2u);  // one warning for both nodes; the third found TYPEWRITER
        }
    EXPECT_EQ(fallbacks, 1u) << b.diagnostics.format(b.loaded.sources);
    // TYPEWRITER is a monospace font: every advance is the same.
    sg::FontStyle mono;
    mono.family = {"NoSuchFamilyXyz", "TYPEWRITER"};
    const FontChoice c = find_font(mono);
    ASSERT_NE(c.font, nullptr);
    EXPECT_TRUE(c.problem.empty()) << c.problem;
    EXPECT_EQ(c.font->advance(U'i'), c.font->advance(U'W')) << c.font->family();
}

TEST(TextScene, FontStyleFieldsAndX3dSolidAreRead) {
    Built b = build(R"(#X3D V3.3 utf8
PROFILE Immersive
Shape { geometry Text { string ["a" "b"] length [3] maxExtent 5 solid TRUE
  fontStyle FontStyle { family ["SANS" "SERIF"] style "BOLDITALIC" size 3 spacing 2
                        justify ["MIDDLE" "END"] horizontal FALSE leftToRight FALSE topToBottom FALSE } } })",
                    "test.x3dv");
    const sg::Text* t = first_text(b.scene);
    ASSERT_NE(t, nullptr);
    EXPECT_EQ(t->strings, (std::vector<std::string>{"a", "b"}));
    EXPECT_EQ(t->length, std::vector<double>{3.0});
    EXPECT_EQ(t->max_extent, 5.0);
    EXPECT_TRUE(t->solid);
    EXPECT_EQ(t->font.family, (std::vector<std::string>{"SANS", "SERIF"}));
    EXPECT_TRUE(t->font.bold && t->font.italic);
    EXPECT_EQ(t->font.size, 3.0);
    EXPECT_EQ(t->font.spacing, 2.0);
    EXPECT_EQ(t->font.major, sg::Justify::Middle);
    EXPECT_EQ(t->font.minor, sg::Justify::End);
    EXPECT_FALSE(t->font.horizontal || t->font.left_to_right || t->font.top_to_bottom);
    // Without a FontStyle: the grammar's defaults (SERIF, size 1, spacing 1, BEGIN FIRST).
    Built d = build("#VRML V2.0 utf8\nShape { geometry Text { string \"a\" } }");
    const sg::Text* dt = first_text(d.scene);
    ASSERT_NE(dt, nullptr);
    EXPECT_EQ(dt->font.family, std::vector<std::string>{"SERIF"});
    EXPECT_EQ(dt->font.size, 1.0);
    EXPECT_EQ(dt->font.spacing, 1.0);
    EXPECT_EQ(dt->font.major, sg::Justify::Begin);
    EXPECT_EQ(dt->font.minor, sg::Justify::First);
    EXPECT_FALSE(dt->solid);
    EXPECT_EQ(d.diagnostics.warning_count(), 0u) << d.diagnostics.format(d.loaded.sources);
}

TEST(TextScene, Vrml1AsciiTextTakesTheFontStyleBeforeIt) {
    Built b = build(R"(#VRML V1.0 ascii
Separator {
  FontStyle { size 4 family TYPEWRITER style (BOLD | ITALIC) }
  AsciiText { string ["one" "two"] spacing 1.25 justification RIGHT width [7 0] }
})");
    const sg::Text* t = first_text(b.scene);
    ASSERT_NE(t, nullptr) << b.loaded.diagnostics.format(b.loaded.sources);
    EXPECT_EQ(t->strings, (std::vector<std::string>{"one", "two"}));
    EXPECT_EQ(t->font.size, 4.0);
    EXPECT_EQ(t->font.spacing, 1.25);
    EXPECT_EQ(t->font.family, std::vector<std::string>{"TYPEWRITER"});
    EXPECT_TRUE(t->font.bold && t->font.italic);
    EXPECT_EQ(t->font.major, sg::Justify::End);
    EXPECT_EQ(t->length, (std::vector<double>{7.0, 0.0}));
    // Without a FontStyle: VRML 1.0's default size 10 (VRML97's is 1).
    Built d = build("#VRML V1.0 ascii\nSeparator { AsciiText { string \"a\" } }");
    const sg::Text* dt = first_text(d.scene);
    ASSERT_NE(dt, nullptr);
    EXPECT_EQ(dt->font.size, 10.0);
    EXPECT_EQ(dt->font.major, sg::Justify::Begin);
}

// Renders `file` twice from the same camera: as it is, and with its Text geometry taken out of
// the typed scene (the file without its Text nodes). Returns the share of pixels covered only in
// the first.
double text_only_share(const fs::path& file, std::string& messages) {
    LoadedScene loaded = load_scene(file);
    Diagnostics diagnostics;
    Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.scene_file = loaded.main_file;
    FlattenStats stats;
    const FlatScene with = flatten_scene(scene, fo, diagnostics, stats);
    for (sg::Geometry& g : scene.geometries)
        if (std::holds_alternative<std::unique_ptr<sg::Text>>(g.shape)) g.shape = std::monostate{};
    const FlatScene without = flatten_scene(scene, fo, diagnostics, stats);
    messages = loaded.diagnostics.format(loaded.sources) + diagnostics.format(loaded.sources);
    RenderOptions o;
    o.width = 160;
    o.height = 120;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(with, o, camera, error)) << error;
    RenderStats rs;
    const Image a = render_image(with, camera, o, nullptr, rs);
    const Image b = render_image(without, camera, o, nullptr, rs);
    size_t only = 0;
    for (size_t p = 0; p < size_t(o.width) * o.height; ++p)
        only += a.rgba[4 * p + 3] > 0.0f && b.rgba[4 * p + 3] == 0.0f;
    return double(only) / (double(o.width) * o.height);
}

TEST(TextCorpus, FilesWhoseGeometryIsTextShowIt) {
    if (!fonts_available()) GTEST_SKIP() << "built without FreeType and fontconfig";
    VR_CORPUS_FOLDER(corpus, "");
    // Each was an empty image (background only) while Text was skipped. The shares are well below
    // what the text covers at this size (thin strokes at 160x120) and far above zero.
    const std::pair<const char*, double> files[] = {
        {"vrml97/castle-engine-demo-models/background/background_one_color.wrl", 0.05},
        {"x3dv/castle-engine-demo-models/text/text.x3dv", 0.01}};
    for (const auto& [name, least] : files) {
        const fs::path file = corpus / name;
        ASSERT_TRUE(fs::exists(file)) << file;
        SCOPED_TRACE(name);
        std::string messages;
        EXPECT_GT(text_only_share(file, messages), least) << messages;
        EXPECT_EQ(messages.find("Text"), std::string::npos) << messages;  // no Text warning
    }
}

}  // namespace
}  // namespace vr
