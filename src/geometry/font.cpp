#include "geometry/font.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <mutex>

#ifdef VRMLRAY_HAVE_FREETYPE
#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H
#endif

namespace vr {

#ifndef VRMLRAY_HAVE_FREETYPE

bool fonts_available() { return false; }
FontChoice find_font(const sg::FontStyle&) {
    return {nullptr, "vrmlray was built without FreeType and fontconfig"};
}

#else

bool fonts_available() { return true; }

namespace {

// Collects an outline's contours, splitting conic and cubic Bezier arcs into chords.
struct OutlineSink {
    std::vector<std::vector<Vec2> >* contours;
    double em;         // font units per em
    double tolerance;  // em
    Vec2 pen{0.0};
    Vec2 at(const FT_Vector* v) const { return Vec2(double(v->x) / em, double(v->y) / em); }
    void line(Vec2 p) {
        contours->back().push_back(p);
        pen = p;
    }
    // Chords of a Bezier arc whose second differences are at most `bend`: n chords keep the
    // distance to the curve below bend / (8 n^2) (the deviation bound of a flattened curve).
    int pieces(double bend) const {
        return std::clamp(int(std::ceil(std::sqrt(bend / (8.0 * tolerance)))), 1, 64);
    }
};

int move_to(const FT_Vector* to, void* user) {
    auto* s = static_cast<OutlineSink*>(user);
    if (!s->contours->empty() && s->contours->back().size() > 1 &&
        s->contours->back().front() == s->contours->back().back())
        s->contours->back().pop_back();  // the closing point repeats the first
    s->contours->emplace_back();
    s->line(s->at(to));
    return 0;
}
int line_to(const FT_Vector* to, void* user) {
    auto* s = static_cast<OutlineSink*>(user);
    s->line(s->at(to));
    return 0;
}
int conic_to(const FT_Vector* control, const FT_Vector* to, void* user) {
    auto* s = static_cast<OutlineSink*>(user);
    const Vec2 p0 = s->pen, p1 = s->at(control), p2 = s->at(to);
    const int n = s->pieces(2.0 * glm::length(p0 - 2.0 * p1 + p2));
    for (int i = 1; i <= n; ++i) {
        const double t = double(i) / n, u = 1.0 - t;
        s->line(i == n ? p2 : u * u * p0 + 2.0 * u * t * p1 + t * t * p2);
    }
    return 0;
}
int cubic_to(const FT_Vector* c1, const FT_Vector* c2, const FT_Vector* to, void* user) {
    auto* s = static_cast<OutlineSink*>(user);
    const Vec2 p0 = s->pen, p1 = s->at(c1), p2 = s->at(c2), p3 = s->at(to);
    const double bend =
        6.0 * std::max(glm::length(p0 - 2.0 * p1 + p2), glm::length(p1 - 2.0 * p2 + p3));
    const int n = s->pieces(bend);
    for (int i = 1; i <= n; ++i) {
        const double t = double(i) / n, u = 1.0 - t;
        s->line(i == n ? p3
                       : u * u * u * p0 + 3.0 * u * u * t * p1 + 3.0 * u * t * t * p2 +
                             t * t * t * p3);
    }
    return 0;
}

class FreeTypeFont final : public Font {
  public:
    FreeTypeFont(FT_Face face, std::string family, std::string file, std::mutex& lock)
        : face_(face), family_(std::move(family)), file_(std::move(file)), lock_(lock) {}
    ~FreeTypeFont() override { FT_Done_Face(face_); }
    std::string family() const override { return family_; }
    std::string file() const override { return file_; }
    double ascender() const override { return double(face_->ascender) / face_->units_per_EM; }
    double descender() const override { return double(face_->descender) / face_->units_per_EM; }
    double advance(char32_t code) const override {
        std::lock_guard<std::mutex> hold(lock_);
        const FT_UInt index = FT_Get_Char_Index(face_, FT_ULong(code));
        if (FT_Load_Glyph(face_, index, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP))
            return 0.0;
        return double(face_->glyph->advance.x) / face_->units_per_EM;
    }
    double kerning(char32_t left, char32_t right) const override {
        std::lock_guard<std::mutex> hold(lock_);
        if (!FT_HAS_KERNING(face_)) return 0.0;
        FT_Vector k{};
        if (FT_Get_Kerning(face_, FT_Get_Char_Index(face_, FT_ULong(left)),
                           FT_Get_Char_Index(face_, FT_ULong(right)), FT_KERNING_UNSCALED, &k))
            return 0.0;
        return double(k.x) / face_->units_per_EM;
    }
    GlyphShape glyph(char32_t code, double tolerance) const override {
        std::lock_guard<std::mutex> hold(lock_);  // an FT_Face is not thread-safe
        GlyphShape g;
        const FT_UInt index = FT_Get_Char_Index(face_, FT_ULong(code));
        if (FT_Load_Glyph(face_, index, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING | FT_LOAD_NO_BITMAP))
            return g;
        const double em = face_->units_per_EM;
        g.advance = double(face_->glyph->advance.x) / em;
        if (face_->glyph->format != FT_GLYPH_FORMAT_OUTLINE) return g;
        OutlineSink sink{&g.contours, em, tolerance};
        FT_Outline_Funcs funcs{};
        funcs.move_to = move_to;
        funcs.line_to = line_to;
        funcs.conic_to = conic_to;
        funcs.cubic_to = cubic_to;
        FT_Outline_Decompose(&face_->glyph->outline, &funcs, &sink);
        if (!g.contours.empty() && g.contours.back().size() > 1 &&
            g.contours.back().front() == g.contours.back().back())
            g.contours.back().pop_back();
        return g;
    }

  private:
    FT_Face face_;
    std::string family_, file_;
    std::mutex& lock_;
};

// FreeType and fontconfig state of the process, and the fonts opened so far.
struct Fonts {
    std::mutex lock;
    FT_Library library = nullptr;
    FcConfig* config = nullptr;
    std::map<std::string, std::shared_ptr<const Font> > by_file;
    Fonts() {
        if (FT_Init_FreeType(&library)) library = nullptr;
        config = FcInitLoadConfigAndFonts();
    }
    ~Fonts() {
        by_file.clear();
        if (config) FcConfigDestroy(config);
        if (library) FT_Done_FreeType(library);
    }
};

Fonts& fonts() {
    static Fonts f;
    return f;
}

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

// VRML97 6.20's generic families as fontconfig's aliases.
const char* generic_alias(const std::string& family) {
    if (family == "SERIF") return "serif";
    if (family == "SANS") return "sans-serif";
    if (family == "TYPEWRITER") return "monospace";
    return nullptr;
}

struct Match {
    std::string file, family;
    int index = 0;
    bool family_matches = false;  // the font fontconfig gave has the asked-for family
};

// Caller holds fonts().lock.
Match match(const std::string& family, bool bold, bool italic) {
    Match m;
    Fonts& f = fonts();
    if (!f.config) return m;
    const char* alias = generic_alias(family);
    FcPattern* pattern = FcPatternCreate();
    FcPatternAddString(pattern, FC_FAMILY,
                       reinterpret_cast<const FcChar8*>(alias ? alias : family.c_str()));
    FcPatternAddInteger(pattern, FC_WEIGHT, bold ? FC_WEIGHT_BOLD : FC_WEIGHT_REGULAR);
    FcPatternAddInteger(pattern, FC_SLANT, italic ? FC_SLANT_ITALIC : FC_SLANT_ROMAN);
    FcPatternAddBool(pattern, FC_OUTLINE, FcTrue);
    FcConfigSubstitute(f.config, pattern, FcMatchPattern);
    FcDefaultSubstitute(pattern);
    FcResult result = FcResultNoMatch;
    FcPattern* found = FcFontMatch(f.config, pattern, &result);
    FcPatternDestroy(pattern);
    if (!found) return m;
    FcChar8* file = nullptr;
    if (FcPatternGetString(found, FC_FILE, 0, &file) == FcResultMatch) m.file = (const char*)file;
    FcPatternGetInteger(found, FC_INDEX, 0, &m.index);
    FcChar8* name = nullptr;
    for (int i = 0; FcPatternGetString(found, FC_FAMILY, i, &name) == FcResultMatch; ++i) {
        if (i == 0) m.family = (const char*)name;
        if (alias || lower((const char*)name) == lower(family)) m.family_matches = true;
    }
    FcPatternDestroy(found);
    return m;
}

// Caller holds fonts().lock.
std::shared_ptr<const Font> open(const Match& m) {
    Fonts& f = fonts();
    if (m.file.empty() || !f.library) return nullptr;
    const std::string key = m.file + "#" + std::to_string(m.index);
    auto it = f.by_file.find(key);
    if (it != f.by_file.end()) return it->second;
    FT_Face face = nullptr;
    if (FT_New_Face(f.library, m.file.c_str(), m.index, &face) || !FT_IS_SCALABLE(face)) {
        if (face) FT_Done_Face(face);
        return f.by_file[key] = nullptr;
    }
    return f.by_file[key] = std::make_shared<FreeTypeFont>(face, m.family, m.file, f.lock);
}

}  // namespace

FontChoice find_font(const sg::FontStyle& style) {
    Fonts& f = fonts();
    std::unique_lock<std::mutex> hold(f.lock);
    std::vector<std::string> families = style.family;
    if (families.empty()) families.push_back("SERIF");
    for (const std::string& family : families) {
        const Match m = match(family, style.bold, style.italic);
        if (!m.family_matches) continue;
        if (auto font = open(m)) return {font, ""};
    }
    std::string asked;
    for (const std::string& family : families)
        asked += (asked.empty() ? "'" : ", '") + family + "'";
    const Match fallback = match("SERIF", style.bold, style.italic);
    if (auto font = open(fallback))
        return {font, "font family " + asked + " not found; '" + font->family() + "' is used"};
    return {nullptr, "no font found for family " + asked + " (fontconfig found no outline font)"};
}

#endif

}  // namespace vr
