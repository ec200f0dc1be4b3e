// Ray-primitive intersection for the tracer's closed set of primitives: spheres (world space),
// quadrics (box, cylinder, cone, ellipsoid in object space) and triangles (world space).
//
// Every routine reports the roots in (0, t_max) only, and decides which roots exist by quantities
// whose sign is reliable for a ray spawned by core/ray.h (the origin is then strictly on one side
// of the surface by more than the rounding error): a ray leaving a surface never re-hits it.
#pragma once
#include <cmath>
#include <cstdint>

#include "core/float_error.h"
#include "core/math.h"
#include "core/ray.h"
#include "render/flat_scene.h"

namespace vr {

enum class PrimKind : uint8_t { Sphere = 0, Quadric = 1, Triangle = 2, Instance = 3 };

// A primitive reference: kind in the top two bits, index into that kind's compact array below.
inline constexpr uint32_t kPrimIndexBits = 30;
inline constexpr uint32_t kPrimIndexMask = (1u << kPrimIndexBits) - 1;
inline uint32_t pack_prim(PrimKind kind, uint32_t index) {
    return (uint32_t(kind) << kPrimIndexBits) | index;
}
inline PrimKind prim_kind(uint32_t ref) { return PrimKind(ref >> kPrimIndexBits); }
inline uint32_t prim_index(uint32_t ref) { return ref & kPrimIndexMask; }

struct SphereGeom {
    Vec3 center;
    double radius;
};

// Parts reported in a quadric hit: Box faces 0..5 = +x,-x,+y,-y,+z,-z; Cylinder 0 side, 1 top,
// 2 bottom; Cone 0 side, 2 bottom; Ellipsoid 0.
enum QuadricPart : uint8_t { kSide = 0, kTop = 1, kBottom = 2 };
inline constexpr uint8_t kPartSide = 1, kPartTop = 2, kPartBottom = 4;

struct QuadricGeom {
    // Cylinders and cones lie within axis_radius of the world line axis_point + s * axis_dir
    // (unit): a ray whose line passes farther from it misses, which a thin bond's box does not
    // show. axis_radius 0: no such bound (other kinds, or a near-singular map).
    Vec3 axis_point{0.0}, axis_dir{0.0};
    double axis_radius = 0.0;
    double object_from_world[3][4];  // rows of the affine map
    Vec3 half;                       // half extents in object space (radius, half height, radius)
    QuadricKind kind;
    uint8_t parts;  // kPartSide | kPartTop | kPartBottom
};
QuadricGeom make_quadric_geom(const Quadric& q);

struct TriangleGeom {
    Vec3 p0, p1, p2;
};

// ---------------------------------------------------------------------------------------------
// Spheres

// Roots of |o + t d - c| = r in (0, t_max), ascending; returns how many (0..2). inv_a = 1/dot(d,
// d).
//
// Discriminant in the b'-form (Haines et al., Ray Tracing Gems ch. 7): r^2 - |l|^2 with l the
// vector from the centre to the ray's closest approach, instead of b^2 - a*c, which cancels
// catastrophically for far tiny spheres. Whether the origin is inside is decided by |o - c|^2 - r^2
// (computed with one rounding by fma); an origin outside keeps both roots, one inside only the far
// one.
inline int sphere_roots(const Vec3& o, const Vec3& d, double inv_a, const Vec3& c, double r,
                        double t_max, double* t) {
    const Vec3 oc = o - c;
    const double b = glm::dot(oc, d);
    const double c0 = std::fma(-r, r, glm::dot(oc, oc));
    const bool outside = c0 > 0.0;
    if (outside && b >= 0.0) return 0;  // outside and heading away
    const double tca = -b * inv_a;
    const Vec3 l = oc + tca * d;
    const double disc = std::fma(r, r, -glm::dot(l, l));
    if (disc < 0.0) return 0;
    const double thc = std::sqrt(disc * inv_a);
    const double t1 = tca + thc;
    int n = 0;
    if (outside) {
        const double t0 = tca - thc;
        if (t0 >= t_max) return 0;
        if (t0 > 0.0) t[n++] = t0;
    }
    if (t1 > 0.0 && t1 < t_max) t[n++] = t1;
    return n;
}

// ---------------------------------------------------------------------------------------------
// Quadrics

// The ray in the quadric's object space. The transformed origin is advanced along the ray by its
// rounding-error bound (pbrt-v3 Transform::operator()(Ray)), so that an origin offset off the
// surface in world space stays off it in object space; `dt` is added back to the object-space t.
struct ObjectRay {
    Vec3 o, d;
    double dt;
};
// object_from_world: the rows of the affine map (a quadric's or a mesh instance's).
inline ObjectRay to_object_space(const double (&object_from_world)[3][4], const Ray& r) {
    ObjectRay out;
    Vec3 err;
    for (int i = 0; i < 3; ++i) {
        const double* m = object_from_world[i];
        double x = m[0] * r.o.x, y = m[1] * r.o.y, z = m[2] * r.o.z;
        out.o[i] = x + y + z + m[3];
        err[i] = gamma_bound(3) * (std::fabs(x) + std::fabs(y) + std::fabs(z) + std::fabs(m[3]));
        out.d[i] = m[0] * r.d.x + m[1] * r.d.y + m[2] * r.d.z;
    }
    double len2 = glm::dot(out.d, out.d);
    out.dt = len2 > 0.0 ? glm::dot(glm::abs(out.d), err) / len2 : 0.0;
    out.o += out.dt * out.d;
    return out;
}
inline ObjectRay to_object_space(const QuadricGeom& q, const Ray& r) {
    return to_object_space(q.object_from_world, r);
}

// An object-space surface point p (error bound p_error) mapped to world space by the affine map w,
// with the bound grown by the map's rounding (pbrt's Transform error propagation) and by
// object_from_world being a computed inverse of w (a point mapped back lands a few ulps of the
// numbers in play off the surface: seen on ellipsoids translated by 1e5).
void to_world_space(const Mat4& w, const Vec3& p, const Vec3& p_error, Vec3& world_p,
                    Vec3& world_error);

// True when the ray's line passes farther than q.axis_radius from q's axis line, so that it meets
// no part of q. Undecided (false) for rays within about 0.06 degrees of the axis direction, where
// the cross product's rounding could mislead, and without a bound. The slack covers the rounding
// of the distance (1e-10 of the numbers in play, far above a few ulps).
inline bool outside_axis_bound(const QuadricGeom& q, const Ray& ray) {
    if (q.axis_radius <= 0.0) return false;  // boxes and ellipsoids pay one comparison
    const Vec3 n = glm::cross(ray.d, q.axis_dir);
    const double nn = glm::dot(n, n);
    if (!(nn > 1e-6 * glm::dot(ray.d, ray.d))) return false;
    const Vec3 w = ray.o - q.axis_point;
    const double along = glm::dot(w, n);  // the lines' distance times |n|
    const double limit = q.axis_radius + 1e-10 * (std::fabs(w.x) + std::fabs(w.y) + std::fabs(w.z));
    return along * along > nn * (limit * limit);
}

// All surface crossings of the quadric in (0, t_max) (world t), unsorted; returns how many (0..4).
int quadric_roots(const QuadricGeom& q, const Ray& ray, double t_max, double* t, uint8_t* part);

// ---------------------------------------------------------------------------------------------
// Triangles: watertight test (Woop, Benthin, Wald 2013), double precision, with a conservative
// check that t is positive (pbrt-v4's bound on t's rounding error).

struct TriangleRay {
    Vec3 o{0.0};
    int kx = 0, ky = 1, kz = 2;
    double sx = 0.0, sy = 0.0, sz = 0.0;
    TriangleRay() = default;  // unused placeholder when a scene has no triangles
    explicit TriangleRay(const Ray& r) : o(r.o) {
        kz = max_dimension(glm::abs(r.d));
        kx = kz == 2 ? 0 : kz + 1;
        ky = kx == 2 ? 0 : kx + 1;
        sz = 1.0 / r.d[kz];
        sx = -r.d[kx] * sz;
        sy = -r.d[ky] * sz;
    }
};

// On a hit, b1 and b2 are the barycentric weights of p1 and p2.
inline bool triangle_hit(const TriangleRay& r, const TriangleGeom& tri, double t_max, double& t_out,
                         double& b1_out, double& b2_out) {
    const Vec3 a = tri.p0 - r.o, b = tri.p1 - r.o, c = tri.p2 - r.o;
    const double az = a[r.kz], bz = b[r.kz], cz = c[r.kz];
    const double ax = a[r.kx] + r.sx * az, ay = a[r.ky] + r.sy * az;
    const double bx = b[r.kx] + r.sx * bz, by = b[r.ky] + r.sy * bz;
    const double cx = c[r.kx] + r.sx * cz, cy = c[r.ky] + r.sy * cz;
    const double e0 = difference_of_products(bx, cy, by, cx);
    const double e1 = difference_of_products(cx, ay, cy, ax);
    const double e2 = difference_of_products(ax, by, ay, bx);
    if ((e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0)) return false;
    const double det = e0 + e1 + e2;
    if (det == 0.0) return false;
    const double z0 = r.sz * az, z1 = r.sz * bz, z2 = r.sz * cz;
    const double t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
    if (det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det)) return false;
    if (det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det)) return false;
    const double inv_det = 1.0 / det;
    const double t = t_scaled * inv_det;
    // Rounding-error bound on t: reject hits not conservatively in front of the origin.
    const double max_z = std::fmax(std::fabs(z0), std::fmax(std::fabs(z1), std::fabs(z2)));
    const double max_x = std::fmax(std::fabs(ax), std::fmax(std::fabs(bx), std::fabs(cx)));
    const double max_y = std::fmax(std::fabs(ay), std::fmax(std::fabs(by), std::fabs(cy)));
    const double delta_z = gamma_bound(3) * max_z;
    const double delta_x = gamma_bound(5) * (max_x + max_z);
    const double delta_y = gamma_bound(5) * (max_y + max_z);
    const double delta_e =
        2.0 * (gamma_bound(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    const double max_e = std::fmax(std::fabs(e0), std::fmax(std::fabs(e1), std::fabs(e2)));
    const double delta_t = 3.0 *
                           (gamma_bound(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) *
                           std::fabs(inv_det);
    if (t <= delta_t) return false;
    t_out = t;
    b1_out = e1 * inv_det;
    b2_out = e2 * inv_det;
    return true;
}

// ---------------------------------------------------------------------------------------------
// What the integrator needs to know about a hit.

// v / |v|, or `fallback` when v has no direction (zero, or not finite).
inline Vec3 safe_normalize(const Vec3& v, const Vec3& fallback) {
    double len2 = glm::dot(v, v);
    if (!(len2 > 0.0) || !std::isfinite(len2)) return fallback;
    return v / std::sqrt(len2);
}

// safe_normalize with the fallback -unit(d), a normal facing a ray along d, worked out only when
// needed: the fallback is almost never taken, and its square root and division are not free.
inline Vec3 normalize_or_facing(const Vec3& v, const Vec3& d) {
    double len2 = glm::dot(v, v);
    if (!(len2 > 0.0) || !std::isfinite(len2)) return -glm::normalize(d);
    return v / std::sqrt(len2);
}

struct SurfaceHit {
    double t = 0.0;
    Vec3 p{0.0};        // world, refined onto the surface
    Vec3 p_error{0.0};  // per-component bound on |p - exact|
    Vec3 ng{0.0, 0.0,
            1.0};  // geometric normal, unit: outward (spheres, quadrics) or front (triangles)
    Vec3 ns{0.0, 0.0, 1.0};  // shading normal, unit, on the same side as ng
    Vec2 uv{0.0};            // texture coordinates before the TextureTransform
    bool has_color = false;  // a Color node gives the diffuse colour
    Vec3 color{1.0};
    bool has_alpha = false;  // the colour is a ColorRGBA: its alpha replaces the transparency
    double alpha = 1.0;
    bool has_fog_depth = false;  // FogCoordinate: fog_depth is the fog amount (render/background.h)
    double fog_depth = 0.0;
    uint32_t shading = 0;
    bool gas = false;  // a gas sphere (docs/rendering.md, Gas mode); the opaque integrator shades
                       // it as opaque
};

// Texture coordinates (inverse trigonometry for round shapes) only when `want_uv`.
SurfaceHit sphere_surface(const Sphere& s, const Ray& ray, double t, bool want_uv = true);
SurfaceHit quadric_surface(const Quadric& q, const QuadricGeom& g, const Ray& ray, double t,
                           uint8_t part, bool want_uv = true);
SurfaceHit triangle_surface(const Mesh& m, uint32_t triangle, const Ray& ray, double t, double b1,
                            double b2);

}  // namespace vr
