// TextureProperties (X3D 19775-1, 18.4.9): boundary modes and filters for the tracer's texture
// look-up (core/texture_sampling.h). What a ray tracer has no use for (mipmaps, compression,
// priority) changes no pixel; what it cannot model is said once.
#include <cmath>

#include "scene/build_internal.h"

namespace vr::detail {

namespace {

struct Label {
    std::string_view text;
    int value;
};

// The value of `text` in `table`, or -1.
int lookup(std::string_view text, std::initializer_list<Label> table) {
    for (const Label& l : table)
        if (l.text == text) return l.value;
    return -1;
}

}  // namespace

void Builder::read_texture_properties(NodeId id, TextureSampling& sampling) {
    if (type(id) != "TextureProperties"_n) {
        warn(id, "wrong-type", "cannot be texture properties; ignored");
        return;
    }
    auto wrap = [&](Name field, TextureWrap& out) {
        const std::vector<std::string> v = strings(id, field);
        const std::string mode = v.empty() ? std::string() : v[0];
        // CLAMP is OpenGL's old GL_CLAMP, which blends the edge with a border that a border
        // width of 0 does not have: what remains is CLAMP_TO_EDGE, as browsers draw it.
        const int m = lookup(mode, {{"REPEAT", int(TextureWrap::Repeat)},
                                    {"CLAMP", int(TextureWrap::ClampToEdge)},
                                    {"CLAMP_TO_EDGE", int(TextureWrap::ClampToEdge)},
                                    {"CLAMP_TO_BOUNDARY", int(TextureWrap::ClampToBoundary)},
                                    {"MIRRORED_REPEAT", int(TextureWrap::MirroredRepeat)}});
        if (m < 0) {
            warn(id, "boundary-mode",
                 "has " + std::string(name_text(field)) + " \"" + mode +
                     "\", which is not REPEAT, CLAMP, CLAMP_TO_EDGE, CLAMP_TO_BOUNDARY or "
                     "MIRRORED_REPEAT; REPEAT is used");
            out = TextureWrap::Repeat;
            return;
        }
        out = TextureWrap(m);
    };
    wrap("boundaryModeS"_n, sampling.wrap_s);
    wrap("boundaryModeT"_n, sampling.wrap_t);

    // A ray samples a point: it has no texel footprint, so it cannot tell magnification from
    // minification. The magnification filter decides (where texels are larger than pixels, the
    // case in which a filter shows); minified texels are averaged by the pixel's samples (--spp).
    auto filter = [&](Name field) {
        const std::vector<std::string> v = strings(id, field);
        const std::string f = v.empty() ? std::string() : v[0];
        if (f.rfind("NEAREST_PIXEL", 0) == 0) return TextureFilter::Nearest;
        if (f.rfind("AVG_PIXEL", 0) == 0 || f == "DEFAULT" || f == "FASTEST" || f == "NICEST")
            return TextureFilter::Linear;
        warn(id, "texture-filter",
             "has " + std::string(name_text(field)) + " \"" + f +
                 "\", which is no X3D filter; AVG_PIXEL (bilinear) is used");
        return TextureFilter::Linear;
    };
    sampling.filter = filter("magnificationFilter"_n);
    // Files often set the magnification filter alone (the one that shows): no warning then.
    const bool min_given = !tree_.get(id, "minificationFilter"_n).is_default;
    if (min_given && filter("minificationFilter"_n) != sampling.filter)
        warn(id, "minification-filter",
             "has a minificationFilter that differs from its magnificationFilter; a ray has no "
             "texel footprint, so the magnification filter is used for both");

    const FieldView border = tree_.get(id, "borderColor"_n);
    if (border.numbers.size() == 4) {
        sampling.border_color =
            Vec4(border.numbers[0], border.numbers[1], border.numbers[2], border.numbers[3]);
        for (int c = 0; c < 4; ++c)
            if (!std::isfinite(sampling.border_color[c])) sampling.border_color[c] = 0.0;
    }
    if (integer(id, "borderWidth"_n) != 0)
        warn(id, "border-width",
             "has borderWidth 1 (the image's outer texels as a border), which vrmlray does not "
             "model; the image is sampled whole");
    if (number(id, "anisotropicDegree"_n) != 1.0)
        warn(id, "anisotropic",
             "has anisotropicDegree, which a ray tracer has no use for (each ray samples a "
             "point; --spp averages); ignored");
}

}  // namespace vr::detail
