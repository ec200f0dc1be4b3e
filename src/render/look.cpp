#include "render/look.h"

#include <algorithm>
#include <cmath>

namespace vr {

double tone_shoulder(double m) {
    if (!(m > kToneKnee)) return m;
    if (m >= kToneWhite) return 1.0;
    const double k = kToneKnee;
    const double x = (m - k) / (1.0 - k), xw = (kToneWhite - k) / (1.0 - k);
    return k + (1.0 - k) * x * (1.0 + x / (xw * xw)) / (1.0 + x);
}

Vec3 tone_hue(const Vec3& c) {
    const double m = std::max({c.x, c.y, c.z});
    if (!(m > kToneKnee) || !std::isfinite(m)) return c;
    return c * (tone_shoulder(m) / m);
}

double auto_light_scale(const std::vector<Light>& lights, bool headlight, double sky_max,
                        double material_ambient_max) {
    auto largest = [](const Vec3& v) { return std::max({v.x, v.y, v.z, 0.0}); };
    auto finite_or_zero = [](double v) { return std::isfinite(v) ? std::max(v, 0.0) : 0.0; };
    std::vector<Vec3> directional;  // w_i l_i
    double free_terms = 0.0;        // point and spot lights, and every ambient term
    auto add = [&](const Light& l, const Vec3& direction) {
        const double rgb = finite_or_zero(largest(l.color));
        const double w = finite_or_zero(l.intensity) * rgb;
        free_terms += finite_or_zero(l.ambient_intensity) * rgb * material_ambient_max;
        if (l.kind == LightKind::Directional) {
            const double len = glm::length(direction);
            if (len > 0.0 && std::isfinite(len)) {
                directional.push_back(w * direction / len);
                return;
            }
        }
        free_terms += w;
    };
    for (const Light& l : lights) add(l, l.direction);
    // The headlight: intensity 1, white, no ambient term; any direction will do, as only the
    // angles between the lights matter and a headlight's follows the view.
    if (headlight) {
        Light h;
        h.ambient_intensity = 0.0;
        add(h, Vec3(0.0, 0.0, -1.0));
    }
    double best = 0.0;
    if (directional.size() <= 16) {
        const uint32_t subsets = 1u << directional.size();
        for (uint32_t s = 1; s < subsets; ++s) {
            Vec3 sum(0.0);
            for (size_t i = 0; i < directional.size(); ++i)
                if (s & (1u << i)) sum += directional[i];
            best = std::max(best, glm::length(sum));
        }
    } else {
        for (const Vec3& d : directional) best += glm::length(d);  // aligned: an upper bound
    }
    const double d = best + free_terms;
    if (!(d > 0.0)) return 1.0;
    const double room = std::max(0.0, 1.0 - finite_or_zero(sky_max));
    return std::min(1.0, room / d);
}

DepthRange scene_depth_range(const FlatScene& scene, const Vec3& eye, const Vec3& forward) {
    DepthRange r;
    auto extend = [&](const Vec3& p, double radius) {
        const double z = glm::dot(p - eye, forward);
        if (!std::isfinite(z) || !std::isfinite(radius)) return;
        r.near = std::min(r.near, z - radius);
        r.far = std::max(r.far, z + radius);
    };
    for (const Sphere& s : scene.spheres)
        if (s.radius > 0.0) extend(s.center, s.radius);
    for (const Quadric& q : scene.quadrics) {
        const Vec3 half = q.size * 0.5;
        for (int c = 0; c < 8; ++c) {
            const Vec3 corner((c & 1) ? half.x : -half.x, (c & 2) ? half.y : -half.y,
                              (c & 4) ? half.z : -half.z);
            extend(Vec3(q.world_from_object * Vec4(corner, 1.0)), 0.0);
        }
    }
    for (const LineSegment& s : scene.segments) extend(s.a, 0.0), extend(s.b, 0.0);
    for (const PointMark& p : scene.points) extend(p.position, 0.0);
    for (const Mesh& m : scene.meshes)
        for (const Vec3& p : m.positions) extend(p, 0.0);
    for (const MeshInstance& in : scene.instances) {
        if (in.prototype >= scene.prototypes.size()) continue;
        for (const Vec3& p : scene.prototypes[in.prototype].positions)
            extend(Vec3(in.world_from_object * Vec4(p, 1.0)), 0.0);
    }
    return r;
}

double depth_cue_fraction(double z, double near, double far) {
    if (!(far > near) || !std::isfinite(z)) return 0.0;
    return std::clamp((z - near) / (far - near), 0.0, 1.0);
}

}  // namespace vr
