// What a surface looks like at a hit: the Material's fields after the VRML97 texture tables
// (4.14.4, tables 4.5 lit and 4.6 unlit; X3D 17.2.2), and texture look-ups.
#pragma once
#include <span>
#include <vector>

#include "core/math.h"
#include "render/flat_scene.h"
#include "render/intersect.h"

namespace vr {

struct SurfaceLook {
    bool lit = true;
    Vec3 diffuse{0.8};  // lit: ODrgb of the lighting equation; unlit: the surface's colour
    Vec3 specular{0.0};
    Vec3 emissive{0.0};
    double ambient_intensity = 0.2;
    double shininess = 0.2;
    double transparency = 0.0;  // 1 - alpha: from the Material, or from the texture's alpha channel
    double reflectivity = 0.0;
    double ior = 1.0;
};

// A texel value with the texture's meaning: rgb (an intensity texture repeats I in all three), a
// (1 without an alpha channel).
struct TexelValue {
    Vec3 rgb{1.0};
    double a = 1.0;
};

// Bilinear look-up at (s, t), t = 0 at the bottom row; repeat or clamp per axis as the texture says
// (always clamp with `clamp`, as for the panorama's cube faces).
TexelValue sample_texture(const Texture& texture, Vec2 st, bool clamp = false);

// Material, texture and Color resolved per the tables:
//   no texture: lit ODrgb = Color or diffuseColor; unlit colour = Color or white (1, 1, 1)
//   1 channel (intensity I):      ODrgb = I * (Color or diffuseColor); unlit I * (Color or white)
//   2 channels (I, A):            as 1 channel, and transparency = 1 - A
//   3 channels (RGB):             ODrgb = RGB (Color ignored)
//   4 channels (RGBA):            ODrgb = RGB, transparency = 1 - A
// Non-finite or out-of-range material values are clamped to their VRML ranges.
SurfaceLook look_up_surface(const FlatScene& scene, const SurfaceHit& hit);
// The same with the materials' looks made beforehand (material_looks: the tracer asks per hit).
SurfaceLook look_up_surface(const FlatScene& scene, std::span<const SurfaceLook> looks,
                            const SurfaceHit& hit);
// What a Material alone decides of the look, clamped: scene.materials' in order, then the default
// Material's (for a shading without a material).
std::vector<SurfaceLook> material_looks(const FlatScene& scene);

}  // namespace vr
