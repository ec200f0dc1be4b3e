// Rays, and how new rays leave a surface without re-hitting it (docs/rendering.md, Numbers).
//
// A hit point p is known only to within a per-component error bound p_error. A new ray starts at
// the corner of that error box that lies on the side of the surface it travels to, pushed out along
// the geometric normal by the bound's projection onto the normal and then rounded one more ulp away
// (pbrt-v4's OffsetRayOrigin idea). The offset therefore scales with the magnitude of the numbers
// involved: 1e-3 scenes and 1e5 scenes behave alike, and no absolute epsilon appears anywhere.
#pragma once
#include <cmath>

#include "core/float_error.h"
#include "core/math.h"

namespace vr {

// o + t*d for t in (0, t_max). d need not be unit length; t is in units of |d|.
struct Ray {
    Vec3 o{0.0};
    Vec3 d{0.0, 0.0, -1.0};
    double t_max = kInf;
    Vec3 at(double t) const { return o + t * d; }
};

// The origin for a ray leaving point p (error bound p_error) in direction w; n is the geometric
// normal (either orientation).
inline Vec3 offset_ray_origin(const Vec3& p, const Vec3& p_error, const Vec3& n, const Vec3& w) {
    double dist = glm::dot(glm::abs(n), p_error);
    Vec3 offset = dist * n;
    if (glm::dot(w, n) < 0.0) offset = -offset;
    Vec3 po = p + offset;
    // The addition above rounds; step one more ulp away from p so the origin is never pulled back.
    for (int i = 0; i < 3; ++i) {
        if (offset[i] > 0.0)
            po[i] = next_up(po[i]);
        else if (offset[i] < 0.0)
            po[i] = next_down(po[i]);
    }
    return po;
}

inline Ray spawn_ray(const Vec3& p, const Vec3& p_error, const Vec3& n, const Vec3& w) {
    Ray r;
    r.o = offset_ray_origin(p, p_error, n, w);
    r.d = w;
    r.t_max = kInf;
    return r;
}

// A ray from a surface point towards a target point (a light), shortened at the target end by the
// rounding error of its coordinates so that a surface passing through the target does not block it.
// d = target - origin, so t = 1 is the target.
inline Ray spawn_ray_to(const Vec3& p, const Vec3& p_error, const Vec3& n, const Vec3& target) {
    Ray r;
    r.o = offset_ray_origin(p, p_error, n, target - p);
    r.d = target - r.o;
    double len = glm::length(r.d);
    double scale = max_component(glm::abs(target)) + max_component(glm::abs(r.o)) + len;
    // 256 ulps of the largest number in play: far above the few-ulp error of any intersection
    // routine's t at the target, far below any real gap between a blocker and the light.
    double margin = len > 0.0 ? gamma_bound(256) * scale / len : 1.0;
    r.t_max = margin < 1.0 ? 1.0 - margin : 0.0;
    return r;
}

}  // namespace vr
