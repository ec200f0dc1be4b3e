#include "render/shading.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

namespace vr {
namespace {

double clamp01(double v) { return std::isfinite(v) ? std::clamp(v, 0.0, 1.0) : 0.0; }
Vec3 clamp01(const Vec3& v) { return Vec3(clamp01(v.x), clamp01(v.y), clamp01(v.z)); }

// The texel of integer index `a` (any integer) along an axis of `size` texels under `wrap`; -1:
// outside the image, where ClampToBoundary samples the border colour.
long long wrap_index(long long a, int size, TextureWrap wrap) {
    switch (wrap) {
        case TextureWrap::Repeat:
            a %= size;
            return a < 0 ? a + size : a;
        case TextureWrap::ClampToEdge:
            return std::clamp<long long>(a, 0, size - 1);
        case TextureWrap::ClampToBoundary:
            return a < 0 || a >= size ? -1 : a;
        case TextureWrap::MirroredRepeat: {
            long long p = a % (2 * size);
            if (p < 0) p += 2 * size;
            return p < size ? p : 2 * size - 1 - p;
        }
    }
    return 0;
}

// The coordinate brought into a range where the texel arithmetic stays exact in integers, without
// changing what it samples: the fraction for Repeat (period 1), the remainder of 2 for
// MirroredRepeat (period 2), [0, 1] for ClampToEdge, [-1, 2] for ClampToBoundary (all border
// beyond).
double reduce(double s, TextureWrap wrap) {
    switch (wrap) {
        case TextureWrap::Repeat:
            return s - std::floor(s);
        case TextureWrap::ClampToEdge:
            return std::clamp(s, 0.0, 1.0);
        case TextureWrap::ClampToBoundary:
            return std::clamp(s, -1.0, 2.0);
        case TextureWrap::MirroredRepeat:
            return s - 2.0 * std::floor(0.5 * s);
    }
    return s;
}

// Texel indices (-1: border) and weight along one axis for a coordinate in texel units (centre of
// texel i at i + 0.5): bilinear between i0 and i1, or the texel x falls in (i0 = i1, frac 0).
void axis_lookup(double x, int size, TextureWrap wrap, TextureFilter filter, long long& i0,
                 long long& i1, double& frac) {
    if (filter == TextureFilter::Nearest) {
        i0 = i1 = wrap_index(static_cast<long long>(std::floor(x)), size, wrap);
        frac = 0.0;
        return;
    }
    const double f = std::floor(x - 0.5);
    frac = (x - 0.5) - f;
    const auto a = static_cast<long long>(f);
    i0 = wrap_index(a, size, wrap);
    i1 = wrap_index(a + 1, size, wrap);
}

}  // namespace

TexelValue sample_texture(const Texture& tex, Vec2 st, bool clamp) {
    TexelValue out;
    const int w = tex.width, h = tex.height, ch = tex.channels;
    if (w <= 0 || h <= 0 || ch < 1 || ch > 4 ||
        tex.texels.size() < size_t(w) * size_t(h) * size_t(ch))
        return out;
    if (!std::isfinite(st.x)) st.x = 0.0;
    if (!std::isfinite(st.y)) st.y = 0.0;
    TextureSampling sampling = tex.sampling;
    if (clamp) sampling.wrap_s = sampling.wrap_t = TextureWrap::ClampToEdge;
    const double s = reduce(st.x, sampling.wrap_s), t = reduce(st.y, sampling.wrap_t);
    long long x0, x1, y0, y1;
    double fx, fy;
    axis_lookup(s * w, w, sampling.wrap_s, sampling.filter, x0, x1, fx);
    axis_lookup(t * h, h, sampling.wrap_t, sampling.filter, y0, y1, fy);
    // The border colour in the texture's channels: I (its red), I A, RGB or RGBA.
    const Vec4& b = sampling.border_color;
    const double border[4][4] = {
        {b.x, 0, 0, 0}, {b.x, b.w, 0, 0}, {b.x, b.y, b.z, 0}, {b.x, b.y, b.z, b.w}};
    double v[4] = {0.0, 0.0, 0.0, 0.0};
    auto add = [&](long long x, long long y, double weight) {
        if (weight == 0.0) return;
        if (x < 0 || y < 0) {
            for (int c = 0; c < ch; ++c) v[c] += weight * border[ch - 1][c];
            return;
        }
        const float* p = tex.texels.data() + (size_t(y) * size_t(w) + size_t(x)) * size_t(ch);
        for (int c = 0; c < ch; ++c) v[c] += weight * p[c];
    };
    add(x0, y0, (1.0 - fx) * (1.0 - fy));
    add(x1, y0, fx * (1.0 - fy));
    add(x0, y1, (1.0 - fx) * fy);
    add(x1, y1, fx * fy);
    switch (ch) {
        case 1:
            out.rgb = Vec3(v[0]);
            break;
        case 2:
            out.rgb = Vec3(v[0]);
            out.a = v[1];
            break;
        case 3:
            out.rgb = Vec3(v[0], v[1], v[2]);
            break;
        default:
            out.rgb = Vec3(v[0], v[1], v[2]);
            out.a = v[3];
            break;
    }
    return out;
}

SurfaceLook material_look(const Material& m) {
    SurfaceLook look;
    look.lit = m.lit;
    look.specular = clamp01(m.specular);
    look.emissive = clamp01(m.emissive);
    look.ambient_intensity = clamp01(m.ambient_intensity);
    look.shininess = clamp01(m.shininess);
    look.transparency = clamp01(m.transparency);
    look.reflectivity = clamp01(m.reflectivity);
    look.ior = std::isfinite(m.ior) && m.ior > 0.0 ? m.ior : 1.0;
    look.diffuse = m.lit ? clamp01(m.diffuse) : Vec3(1.0);
    return look;
}

std::vector<SurfaceLook> material_looks(const FlatScene& scene) {
    std::vector<SurfaceLook> looks;
    looks.reserve(scene.materials.size() + 1);
    for (const Material& m : scene.materials) looks.push_back(material_look(m));
    looks.push_back(material_look(Material()));
    return looks;
}

SurfaceLook look_up_surface(const FlatScene& scene, std::span<const SurfaceLook> looks,
                            const SurfaceHit& hit) {
    static const Material kDefault;
    size_t mi = scene.materials.size();  // no material: the default's look, last in `looks`
    if (hit.shading < scene.shadings.size() &&
        scene.shadings[hit.shading].material < scene.materials.size())
        mi = scene.shadings[hit.shading].material;
    const Material& m = mi < scene.materials.size() ? scene.materials[mi] : kDefault;
    SurfaceLook look = looks[mi];
    // ColorRGBA (X3D 11.4.2): the colour's alpha is the surface's opacity, in place of the
    // Material's transparency; a texture's alpha below still replaces it in turn.
    if (hit.has_alpha) look.transparency = 1.0 - clamp01(hit.alpha);

    // The colour the texture modulates, or the colour itself without a texture.
    if (hit.has_color) look.diffuse = clamp01(hit.color);
    const Vec3 base = look.diffuse;
    if (m.texture >= 0 && size_t(m.texture) < scene.textures.size()) {
        const Texture& tex = scene.textures[size_t(m.texture)];
        Vec3 st = m.texture_transform * Vec3(hit.uv, 1.0);
        TexelValue tv = sample_texture(tex, Vec2(st.x, st.y));
        // A grey texture modulates in every version; an RGB one replaces the colour in VRML97
        // and X3D 3 (17.2.2.4 there) and modulates it in X3D 4.
        if (tex.channels <= 2)
            look.diffuse = clamp01(tv.rgb.x) * base;
        else if (m.texture_modulates)
            look.diffuse = clamp01(tv.rgb) * base;
        else
            look.diffuse = clamp01(tv.rgb);
        if (tex.channels == 2 || tex.channels == 4) look.transparency = 1.0 - clamp01(tv.a);
    }
    return look;
}

SurfaceLook look_up_surface(const FlatScene& scene, const SurfaceHit& hit) {
    return look_up_surface(scene, material_looks(scene), hit);
}

}  // namespace vr
