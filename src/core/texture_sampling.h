// How a texture is sampled: X3D TextureProperties (19775-1, 18.4.9) boundary modes and filters, in
// the form both the scene (which reads them) and the tracer (which samples) use. The defaults are
// what a texture without TextureProperties gets: bilinear, repeated or clamped to the edge texels
// as its repeatS/repeatT say.
#pragma once
#include <cstdint>

#include "core/math.h"

namespace vr {

enum class TextureWrap : uint8_t {
    Repeat,           // REPEAT
    ClampToEdge,      // CLAMP_TO_EDGE, and CLAMP (see docs/input.md): never a texel from outside
    ClampToBoundary,  // CLAMP_TO_BOUNDARY: outside the image the samples are borderColor
    MirroredRepeat,   // MIRRORED_REPEAT: every other copy of the image mirrored
};

enum class TextureFilter : uint8_t {
    Linear,   // AVG_PIXEL (and DEFAULT, FASTEST, NICEST: see docs/input.md)
    Nearest,  // NEAREST_PIXEL: the texel the point falls in
};

struct TextureSampling {
    TextureWrap wrap_s = TextureWrap::Repeat;
    TextureWrap wrap_t = TextureWrap::Repeat;
    TextureFilter filter = TextureFilter::Linear;
    Vec4 border_color{0.0};  // RGBA, for ClampToBoundary
    bool operator==(const TextureSampling&) const = default;
};

}  // namespace vr
