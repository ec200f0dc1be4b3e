#include "geometry/text.h"

#include <algorithm>
#include <unordered_map>

#include "geometry/fill.h"

namespace vr {

std::u32string decode_utf8(const std::string& text) {
    std::u32string out;
    const auto* s = reinterpret_cast<const unsigned char*>(text.data());
    const size_t n = text.size();
    for (size_t i = 0; i < n;) {
        const unsigned char c = s[i];
        const int extra = c < 0x80         ? 0
                          : (c >> 5) == 6  ? 1
                          : (c >> 4) == 14 ? 2
                          : (c >> 3) == 30 ? 3
                                           : -1;
        char32_t code = extra == 0 ? c : extra == 1 ? c & 0x1F : extra == 2 ? c & 0x0F : c & 0x07;
        bool ok = extra >= 0 && i + extra < n;
        for (int k = 1; ok && k <= extra; ++k) {
            ok = (s[i + k] & 0xC0) == 0x80;
            code = (code << 6) | (s[i + k] & 0x3F);
        }
        // Overlong forms, surrogates and values past U+10FFFF are malformed too.
        static const char32_t kLeast[4] = {0, 0x80, 0x800, 0x10000};
        if (ok && (code < kLeast[extra] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)))
            ok = false;
        out.push_back(ok ? code : U'\uFFFD');
        i += ok ? size_t(extra) + 1 : 1;
    }
    return out;
}

namespace {

struct Line {
    std::u32string codes;
    std::vector<double> advances;  // object units along the major axis, before `factor`
    double factor = 1.0;           // length / maxExtent scaling along the major axis
    double extent() const {
        double sum = 0.0;
        for (double a : advances) sum += a;
        return sum * factor;
    }
};

// Kerning moves a pair closer (or apart) by a distance the font gives for the pair as seen, left
// glyph first: it joins the advance of the one on the left, which reading right to left is the
// later character.
void add_kerning(Line& line, const Font& font, const sg::FontStyle& f) {
    for (size_t k = 0; k + 1 < line.codes.size(); ++k) {
        const char32_t a = line.codes[k], b = line.codes[k + 1];
        if (f.left_to_right)
            line.advances[k] += font.kerning(a, b) * f.size;
        else
            line.advances[k + 1] += font.kerning(b, a) * f.size;
    }
}

std::vector<Line> measured_lines(const sg::Text& text, const Font& font) {
    const sg::FontStyle& f = text.font;
    std::vector<Line> lines(text.strings.size());
    double longest = 0.0;
    for (size_t i = 0; i < lines.size(); ++i) {
        Line& line = lines[i];
        line.codes = decode_utf8(text.strings[i]);
        for (char32_t c : line.codes)
            line.advances.push_back(f.horizontal ? font.advance(c) * f.size : f.size);
        if (f.horizontal) add_kerning(line, font, f);
        const double natural = line.extent();
        if (i < text.length.size() && text.length[i] > 0.0 && natural > 0.0)
            line.factor = text.length[i] / natural;
        longest = std::max(longest, line.extent());
    }
    if (text.max_extent > 0.0 && longest > text.max_extent)
        for (Line& line : lines) line.factor *= text.max_extent / longest;
    return lines;
}

// Where the reading of a line of `extent` starts along its axis, whose reading direction is `dir`.
double major_start(sg::Justify j, double extent, double dir) {
    if (j == sg::Justify::End) return -dir * extent;
    if (j == sg::Justify::Middle) return -0.5 * dir * extent;
    return 0.0;
}

TextLayout horizontal_layout(const sg::Text& text, const Font& font, std::vector<Line>& lines) {
    const sg::FontStyle& f = text.font;
    const double dir = f.left_to_right ? 1.0 : -1.0, step = f.top_to_bottom ? -1.0 : 1.0;
    const double asc = font.ascender() * f.size, desc = font.descender() * f.size;
    const double first = 0.0,
                 last = step * double(lines.empty() ? 0 : lines.size() - 1) * f.spacing * f.size;
    double shift = 0.0;  // along y, for the minor justification
    if (f.minor == sg::Justify::Begin) shift = f.top_to_bottom ? -(first + asc) : -(first + desc);
    if (f.minor == sg::Justify::End) shift = f.top_to_bottom ? -(last + desc) : -(last + asc);
    if (f.minor == sg::Justify::Middle)
        shift = -0.5 * (std::max(first, last) + asc + std::min(first, last) + desc);
    TextLayout out;
    for (size_t i = 0; i < lines.size(); ++i) {
        const Line& line = lines[i];
        const double y = step * double(i) * f.spacing * f.size + shift;
        const double start = major_start(f.major, line.extent(), dir);
        if (i == 0) out.texture_origin = Vec2(std::min(start, start + dir * line.extent()), y);
        double pen = start;
        for (size_t k = 0; k < line.codes.size(); ++k) {
            const double advance = line.advances[k] * line.factor;
            if (dir < 0.0) pen -= advance;
            out.glyphs.push_back(
                {i, line.codes[k], Vec2(pen, y), Vec2(f.size * line.factor, f.size)});
            if (dir > 0.0) pen += advance;
        }
    }
    return out;
}

TextLayout vertical_layout(const sg::Text& text, const Font& font, std::vector<Line>& lines) {
    const sg::FontStyle& f = text.font;
    const double dir = f.top_to_bottom ? -1.0 : 1.0, step = f.left_to_right ? 1.0 : -1.0;
    const double asc = font.ascender() * f.size, desc = font.descender() * f.size;
    const double last = step * double(lines.empty() ? 0 : lines.size() - 1) * f.spacing * f.size;
    const double left = std::min(0.0, last), right = std::max(0.0, last) + f.size;
    double shift = 0.0;  // along x, for the minor justification
    if (f.minor == sg::Justify::Begin && !f.left_to_right) shift = -f.size;
    if (f.minor == sg::Justify::End) shift = f.left_to_right ? -(last + f.size) : -last;
    if (f.minor == sg::Justify::Middle) shift = -0.5 * (left + right);
    TextLayout out;
    for (size_t i = 0; i < lines.size(); ++i) {
        const Line& line = lines[i];
        const double x = step * double(i) * f.spacing * f.size + shift;
        const double start = major_start(f.major, line.extent(), dir);
        if (i == 0) out.texture_origin = Vec2(x, std::min(start, start + dir * line.extent()));
        double pen = start;  // the cell's edge where reading enters it
        for (size_t k = 0; k < line.codes.size(); ++k) {
            const double cell = line.advances[k] * line.factor;
            const double baseline = dir < 0.0 ? pen - asc * line.factor : pen - desc * line.factor;
            out.glyphs.push_back(
                {i, line.codes[k], Vec2(x, baseline), Vec2(f.size, f.size * line.factor)});
            pen += dir * cell;
        }
    }
    return out;
}

}  // namespace

TextLayout layout_text(const sg::Text& text, const Font& font) {
    std::vector<Line> lines = measured_lines(text, font);
    return text.font.horizontal ? horizontal_layout(text, font, lines)
                                : vertical_layout(text, font, lines);
}

TriMesh text_mesh(const sg::Text& text, bool want_uvs, NodeReport& report) {
    const FontChoice choice = find_font(text.font);
    if (!choice.font) {
        report.warn("no-font", choice.problem + "; not rendered");
        return {};
    }
    if (!choice.problem.empty()) report.warn("font-fallback", choice.problem);
    const TextLayout layout = layout_text(text, *choice.font);
    // Curves are flattened to 1/1000 em: far below a pixel unless one glyph spans 1000 pixels.
    constexpr double kTolerance = 1e-3;
    std::unordered_map<char32_t, FlatTriangles> filled;
    TriMesh mesh;
    mesh.solid = text.solid;
    for (const PlacedGlyph& g : layout.glyphs) {
        auto it = filled.find(g.code);
        if (it == filled.end())
            it = filled
                     .emplace(g.code, fill_nonzero(choice.font->glyph(g.code, kTolerance).contours))
                     .first;
        const FlatTriangles& shape = it->second;
        const uint32_t base = static_cast<uint32_t>(mesh.positions.size());
        for (const Vec2& p : shape.points) {
            const Vec2 at = g.origin + g.scale * p;
            mesh.positions.emplace_back(at.x, at.y, 0.0);
        }
        for (uint32_t index : shape.triangles) mesh.triangles.push_back(base + index);
    }
    if (want_uvs) {
        mesh.uvs.reserve(mesh.triangles.size());
        for (uint32_t index : mesh.triangles) {
            const Vec3& p = mesh.positions[index];
            mesh.uvs.push_back((Vec2(p.x, p.y) - layout.texture_origin) / text.font.size);
        }
    }
    return mesh;
}

}  // namespace vr
