// Fonts for Text: FontStyle families found through fontconfig, glyph outlines and metrics read by
// FreeType, unhinted and unscaled (in em units: 1 is the font's em square), so that a glyph's
// geometry does not depend on any pixel size.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "scene/scene.h"

namespace vr {

struct GlyphShape {
    std::vector<std::vector<Vec2>> contours;  // closed, curves flattened; nonzero winding fills
    double advance = 0.0;                     // horizontal advance, em units (no kerning)
};

class Font {
  public:
    virtual ~Font() = default;
    virtual std::string family() const = 0;  // what fontconfig matched, e.g. "DejaVu Sans"
    virtual std::string file() const = 0;
    virtual double ascender() const = 0;              // em units, above the baseline (> 0)
    virtual double descender() const = 0;             // em units, below the baseline (< 0)
    virtual double advance(char32_t code) const = 0;  // em units, no kerning
    // Em units added to `left`'s advance when `right` follows it on screen (the font's kern table;
    // 0 without one; GPOS kerning would need a shaper).
    virtual double kerning(char32_t left, char32_t right) const = 0;
    // The glyph of a Unicode code point (the font's missing-glyph box if it has none). Curves are
    // split until no chord is further than `tolerance` em from its curve.
    virtual GlyphShape glyph(char32_t code, double tolerance) const = 0;
};

struct FontChoice {
    std::shared_ptr<const Font> font;  // null: no font at all (the Text is not drawn)
    std::string problem;               // non-empty: why a fallback was used, or why there is none
};

// The first family of `style` (SERIF, SANS, TYPEWRITER or a font name fontconfig knows, in order)
// with its bold/italic; a name fontconfig does not have falls back to the generic SERIF with
// `problem` saying so. Fonts are opened once a process (thread-safe).
FontChoice find_font(const sg::FontStyle& style);

// False when vrmlray was built without FreeType and fontconfig.
bool fonts_available();

}  // namespace vr
