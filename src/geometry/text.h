// Text (VRML97 6.47, X3D 15.4.2) as flat triangles in the z = 0 plane, front face +z: the glyphs
// of a font fontconfig finds (geometry/font.h), laid out by FontStyle's rules and filled with their
// holes (geometry/fill.h).
//
// Layout, in units of FontStyle.size (the em square of the font is size high):
// * Horizontal text: line i's baseline is at y = -i * spacing (topToBottom FALSE: +i * spacing);
//   glyphs advance by their font advance, without kerning; leftToRight FALSE runs each line from
//   right to left (its first character rightmost).
// * `length[i]` > 0 scales line i along its major axis to that length; then, if `maxExtent` > 0
//   and the longest line is longer, every line is compressed by the same factor to fit.
// * Major justify: BEGIN and FIRST start the line at x = 0 in its reading direction, END ends it
//   there, MIDDLE centres it. Minor justify: FIRST puts the first baseline at y = 0, BEGIN the
//   first line's ascender, END the last line's descender, MIDDLE the middle between those two.
// * Vertical text (horizontal FALSE): each string is a column (columns advance by spacing along
//   +x, or -x with leftToRight FALSE); characters advance by one size along -y (topToBottom FALSE:
//   +y) with their baseline one ascender below the cell top; major justify acts along y and minor
//   along x as for horizontal text.
// * Texture coordinates (VRML97 6.47): s along +x and t along +y, one unit per size, with (0, 0)
//   at the first line's origin.
#pragma once
#include <string>
#include <vector>

#include "geometry/font.h"
#include "geometry/tri_mesh.h"
#include "scene/report.h"
#include "scene/scene.h"

namespace vr {

// Code points of a UTF-8 string; a malformed sequence is one U+FFFD.
std::u32string decode_utf8(const std::string& text);

// Where each glyph of the text goes (before filling): the layout alone, for tests and for
// text_mesh.
struct PlacedGlyph {
    size_t line = 0;
    char32_t code = 0;
    Vec2 origin{0.0};  // the glyph's origin (baseline, left side bearing origin), object units
    Vec2 scale{1.0};   // em -> object units along x and y (length and maxExtent change one)
};
struct TextLayout {
    std::vector<PlacedGlyph> glyphs;
    Vec2 texture_origin{0.0};
};
TextLayout layout_text(const sg::Text& text, const Font& font);

// The text's triangles; warns (once per cause) when the font falls back or none is found.
TriMesh text_mesh(const sg::Text& text, bool want_uvs, NodeReport& report);

}  // namespace vr
