// Quadric roots and the surface data (refined point, error bound, normals, texture coordinates) of
// every primitive kind. Texture coordinates follow the VRML97 geometry node descriptions (6.3 Box,
// 6.17 Cone, 6.18 Cylinder, 6.42 Sphere).
#include "render/intersect.h"

#include <algorithm>
#include <cmath>

namespace vr {
namespace {

constexpr double kTwoPi = 2.0 * kPi;

// Longitude around +y, 0 at the -z seam and increasing counterclockwise seen from +y (VRML's wrap).
inline double wrap_s(double x, double z) { return std::atan2(x, z) / kTwoPi + 0.5; }

}  // namespace

QuadricGeom make_quadric_geom(const Quadric& q) {
    QuadricGeom g;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) g.object_from_world[i][j] = q.object_from_world[j][i];
    g.half = q.size * 0.5;
    g.kind = q.kind;
    g.parts =
        uint8_t((q.side ? kPartSide : 0) | (q.top ? kPartTop : 0) | (q.bottom ? kPartBottom : 0));
    if (q.kind == QuadricKind::Cylinder || q.kind == QuadricKind::Cone) {
        // Object points (x, y, z) with x^2 + z^2 <= r^2 map to at most sigma * r from the axis
        // line, sigma the largest singular value of the map's x and z columns (from their 2x2
        // Gram matrix). The bound is widened by 1e-6: the exact test uses the computed inverse
        // object_from_world, whose inverse is world_from_object only to rounding; a map whose
        // axis column and cross-section differ in scale by more than 1e6 gets no bound.
        const Vec3 ex(q.world_from_object[0]), ey(q.world_from_object[1]),
            ez(q.world_from_object[2]);
        const double g11 = glm::dot(ex, ex), g22 = glm::dot(ez, ez), g12 = glm::dot(ex, ez);
        const double half_gap = 0.5 * (g11 - g22);
        const double sigma =
            std::sqrt(0.5 * (g11 + g22) + std::sqrt(half_gap * half_gap + g12 * g12));
        const double ey_len = glm::length(ey);
        const double radius = g.half.x, half_height = g.half.y;
        const bool conditioned = sigma > 0.0 && ey_len > 1e-6 * sigma && ey_len < 1e6 * sigma;
        const Vec3 origin(q.world_from_object[3]);
        const double bound = (radius * sigma + 1e-12 * half_height * ey_len) * (1.0 + 1e-6);
        if (conditioned && radius > 0.0 && std::isfinite(bound) &&
            std::isfinite(glm::dot(origin, origin))) {
            g.axis_point = origin;
            g.axis_dir = ey / ey_len;
            g.axis_radius = bound;
        }
    }
    return g;
}

namespace {

// The roots of a quadric as quadric_roots gives them: those in (0, tm) of the object-space ray,
// moved by dt into the world ray's t, with the part each lies on.
struct QuadricRoots {
    double* t;
    uint8_t* part;
    double tm, dt;
    int n = 0;
    void push(double tt, uint8_t p) {
        if (tt > 0.0 && tt < tm) {
            t[n] = tt + dt;
            part[n] = p;
            ++n;
        }
    }
};

void box_roots(const Vec3& h, const Vec3& o, const Vec3& d, uint8_t parts, QuadricRoots& out) {
    double t_near = -kInf, t_far = kInf;
    uint8_t f_near = 0, f_far = 0;
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0) {
            if (o[k] < -h[k] || o[k] > h[k]) return;
            continue;
        }
        // (face - o) is exact in sign, so an origin just outside a face stays outside.
        double inv = 1.0 / d[k];
        double t_lo = (-h[k] - o[k]) * inv, t_hi = (h[k] - o[k]) * inv;
        uint8_t f_lo = uint8_t(2 * k + 1), f_hi = uint8_t(2 * k);
        // A flat box (size 0 on axis k) has t_lo == t_hi: the face the ray meets is the
        // one it comes from, +k when it travels towards -k.
        if (t_lo > t_hi || (t_lo == t_hi && d[k] < 0.0)) {
            std::swap(t_lo, t_hi);
            std::swap(f_lo, f_hi);
        }
        if (t_lo > t_near) {
            t_near = t_lo;
            f_near = f_lo;
        }
        if (t_hi < t_far) {
            t_far = t_hi;
            f_far = f_hi;
        }
    }
    if (t_near > t_far) return;
    out.push(t_near, f_near);
    out.push(t_far, f_far);
}

void cylinder_roots(const Vec3& h, const Vec3& o, const Vec3& d, uint8_t parts, QuadricRoots& out) {
    const double radius = h.x, half_height = h.y;
    if (parts & kPartSide) {
        const double a = d.x * d.x + d.z * d.z;
        const double b = o.x * d.x + o.z * d.z;
        const double c0 = std::fma(-radius, radius, o.x * o.x + o.z * o.z);
        const bool outside = c0 > 0.0;
        if (a > 0.0 && !(outside && b >= 0.0)) {
            const double tca = -b / a;
            const double lx = o.x + tca * d.x, lz = o.z + tca * d.z;
            const double disc = std::fma(radius, radius, -(lx * lx + lz * lz));
            if (disc >= 0.0) {
                const double thc = std::sqrt(disc / a);
                if (outside) {
                    double t0 = tca - thc;
                    if (std::fabs(o.y + t0 * d.y) <= half_height) out.push(t0, kSide);
                }
                double t1 = tca + thc;
                if (std::fabs(o.y + t1 * d.y) <= half_height) out.push(t1, kSide);
            }
        }
    }
    if (d.y != 0.0) {
        const double r2 = radius * radius;
        if (parts & kPartTop) {
            double tt = (half_height - o.y) / d.y;
            double x = o.x + tt * d.x, z = o.z + tt * d.z;
            if (x * x + z * z <= r2) out.push(tt, kTop);
        }
        if (parts & kPartBottom) {
            double tt = (-half_height - o.y) / d.y;
            double x = o.x + tt * d.x, z = o.z + tt * d.z;
            if (x * x + z * z <= r2) out.push(tt, kBottom);
        }
    }
}

void cone_roots(const Vec3& h, const Vec3& o, const Vec3& d, uint8_t parts, QuadricRoots& out) {
    // Apex at y = +H, base circle of radius R at y = -H: x^2 + z^2 = k^2 (H - y)^2, k = R /
    // 2H.
    const double radius = h.x, half_height = h.y;
    if ((parts & kPartSide) && half_height > 0.0) {
        const double k = radius / (2.0 * half_height), k2 = k * k;
        const double w = half_height - o.y;  // height below the apex
        const double a = d.x * d.x + d.z * d.z - k2 * d.y * d.y;
        const double b = o.x * d.x + o.z * d.z + k2 * w * d.y;
        const double rho = std::sqrt(o.x * o.x + o.z * o.z), kw = k * std::fabs(w);
        const double c0 = (rho - kw) * (rho + kw);  // sign: outside (> 0) or inside the cone
        double roots[2];
        int m = 0;
        if (a == 0.0) {
            if (b != 0.0) roots[m++] = -c0 / (2.0 * b);
        } else {
            const double disc = b * b - a * c0;
            if (disc >= 0.0) {
                // Stable pair: q/a and c/q never subtract nearly equal numbers.
                const double qq = -(b + std::copysign(std::sqrt(disc), b));
                roots[m++] = qq / a;
                if (qq != 0.0) roots[m++] = c0 / qq;
            }
        }
        for (int i = 0; i < m; ++i)
            if (std::fabs(o.y + roots[i] * d.y) <= half_height) out.push(roots[i], kSide);
    }
    if ((parts & kPartBottom) && d.y != 0.0) {
        double tt = (-half_height - o.y) / d.y;
        double x = o.x + tt * d.x, z = o.z + tt * d.z;
        if (x * x + z * z <= radius * radius) out.push(tt, kBottom);
    }
}

}  // namespace

int quadric_roots(const QuadricGeom& q, const Ray& ray, double t_max, double* t, uint8_t* part) {
    if (outside_axis_bound(q, ray)) return 0;
    const ObjectRay r = to_object_space(q, ray);
    const Vec3& o = r.o;
    const Vec3& d = r.d;
    QuadricRoots roots{t, part, t_max - r.dt, r.dt};
    const Vec3& h = q.half;
    switch (q.kind) {
        case QuadricKind::Box:
            box_roots(h, o, d, q.parts, roots);
            break;
        case QuadricKind::Cylinder:
            cylinder_roots(h, o, d, q.parts, roots);
            break;
        case QuadricKind::Cone:
            cone_roots(h, o, d, q.parts, roots);
            break;
        case QuadricKind::Ellipsoid: {
            // Scaled to the unit sphere; t is unchanged by the scaling.
            if (!(h.x > 0.0 && h.y > 0.0 && h.z > 0.0)) return 0;
            const Vec3 os = o / h, ds = d / h;
            double ell[2];
            int m = sphere_roots(os, ds, 1.0 / glm::dot(ds, ds), Vec3(0.0), 1.0, roots.tm, ell);
            for (int i = 0; i < m; ++i) roots.push(ell[i], kSide);
            return roots.n;
        }
    }
    return roots.n;
}

SurfaceHit sphere_surface(const Sphere& s, const Ray& ray, double t, bool want_uv) {
    SurfaceHit hit;
    hit.t = t;
    Vec3 n = normalize_or_facing(ray.at(t) - s.center, ray.d);
    // Refinement: reprojecting onto the sphere leaves only the rounding of c + r*n.
    hit.p = s.center + s.radius * n;
    hit.p_error = gamma_bound(6) * (glm::abs(s.center) + Vec3(s.radius));
    hit.ng = n;
    hit.ns = n;
    if (want_uv) hit.uv = Vec2(wrap_s(n.x, n.z), 0.5 + std::asin(std::clamp(n.y, -1.0, 1.0)) / kPi);
    hit.shading = s.shading;
    hit.gas = s.gas;
    return hit;
}

void to_world_space(const Mat4& w, const Vec3& p, const Vec3& p_error, Vec3& world_p,
                    Vec3& world_error) {
    for (int i = 0; i < 3; ++i) {
        double x = w[0][i] * p.x, y = w[1][i] * p.y, z = w[2][i] * p.z;
        world_p[i] = x + y + z + w[3][i];
        world_error[i] =
            gamma_bound(3) * (std::fabs(x) + std::fabs(y) + std::fabs(z) + std::fabs(w[3][i])) +
            (1.0 + gamma_bound(3)) *
                (std::fabs(w[0][i]) * p_error.x + std::fabs(w[1][i]) * p_error.y +
                 std::fabs(w[2][i]) * p_error.z) +
            gamma_bound(32) * (std::fabs(world_p[i]) + std::fabs(w[3][i]));
    }
}

SurfaceHit quadric_surface(const Quadric& q, const QuadricGeom& g, const Ray& ray, double t,
                           uint8_t part, bool want_uv) {
    SurfaceHit hit;
    hit.t = t;
    hit.shading = q.shading;
    const ObjectRay r = to_object_space(g, ray);
    Vec3 p = r.o + (t - r.dt) * r.d;  // object space
    Vec3 n(0.0, 1.0, 0.0);            // object-space normal (not yet unit for ellipsoids)
    Vec2 uv(0.0);
    const Vec3& h = g.half;
    switch (q.kind) {
        case QuadricKind::Box: {
            int axis = part / 2;
            double sign = (part % 2 == 0) ? 1.0 : -1.0;
            p = glm::clamp(p, -h, h);
            p[axis] = sign * h[axis];  // refined: exactly on the face plane
            n = Vec3(0.0);
            n[axis] = sign;
            auto unit = [&](int k) { return h[k] > 0.0 ? 0.5 * (p[k] / h[k] + 1.0) : 0.5; };
            double ux = unit(0), uy = unit(1), uz = unit(2);
            switch (part) {
                case 0:
                    uv = Vec2(1.0 - uz, uy);
                    break;  // +x: s along -z
                case 1:
                    uv = Vec2(uz, uy);
                    break;  // -x: s along +z
                case 2:
                    uv = Vec2(ux, 1.0 - uz);
                    break;  // +y: s along +x, t along -z
                case 3:
                    uv = Vec2(ux, uz);
                    break;  // -y: s along +x, t along +z
                case 4:
                    uv = Vec2(ux, uy);
                    break;  // +z (front)
                default:
                    uv = Vec2(1.0 - ux, uy);
                    break;  // -z: s along -x
            }
            break;
        }
        case QuadricKind::Cylinder:
        case QuadricKind::Cone: {
            const double radius = h.x, half_height = h.y;
            if (part == kSide) {
                double rho = std::sqrt(p.x * p.x + p.z * p.z);
                if (q.kind == QuadricKind::Cylinder) {
                    if (rho > 0.0) {
                        p.x *= radius / rho;
                        p.z *= radius / rho;
                    }
                    p.y = std::clamp(p.y, -half_height, half_height);
                    n = Vec3(p.x, 0.0, p.z);
                } else {
                    // Project (rho, y) onto the generator line from the apex (0, H) to (R, -H).
                    double len = std::hypot(radius, 2.0 * half_height);
                    double gx = radius / len, gy = -2.0 * half_height / len;
                    double s = std::clamp(rho * gx + (p.y - half_height) * gy, 0.0, len);
                    double ux = rho > 0.0 ? p.x / rho : 0.0, uz = rho > 0.0 ? p.z / rho : 0.0;
                    p.x = ux * s * gx;
                    p.z = uz * s * gx;
                    p.y = half_height + s * gy;
                    // Outward normal: perpendicular to the generator in the (rho, y) half-plane.
                    n = rho > 0.0 ? Vec3(-gy * ux, gx, -gy * uz) : Vec3(0.0, 1.0, 0.0);
                }
                if (want_uv)
                    uv = Vec2(wrap_s(p.x, p.z),
                              half_height > 0.0 ? 0.5 * (p.y / half_height + 1.0) : 0.5);
            } else {
                double sign = part == kTop ? 1.0 : -1.0;
                p.y = sign * half_height;
                n = Vec3(0.0, sign, 0.0);
                double sx = radius > 0.0 ? 0.5 * (p.x / radius + 1.0) : 0.5;
                double sz = radius > 0.0 ? 0.5 * (p.z / radius + 1.0) : 0.5;
                uv = part == kTop ? Vec2(sx, 1.0 - sz) : Vec2(sx, sz);
            }
            break;
        }
        case QuadricKind::Ellipsoid: {
            Vec3 u = safe_normalize(p / h, Vec3(0.0, 1.0, 0.0));
            p = u * h;
            n = u / h;
            if (want_uv)
                uv = Vec2(wrap_s(u.x, u.z), 0.5 + std::asin(std::clamp(u.y, -1.0, 1.0)) / kPi);
            break;
        }
    }
    to_world_space(q.world_from_object, p, gamma_bound(4) * glm::abs(p), hit.p, hit.p_error);
    const Mat3 normal_from_object = glm::transpose(Mat3(q.object_from_world));
    hit.ng = normalize_or_facing(normal_from_object * n, ray.d);
    hit.ns = hit.ng;
    hit.uv = uv;
    return hit;
}

SurfaceHit triangle_surface(const Mesh& m, uint32_t triangle, const Ray& ray, double t, double b1,
                            double b2) {
    SurfaceHit hit;
    hit.t = t;
    hit.shading = m.shading;
    const uint32_t c0 = 3 * triangle;
    const Vec3& p0 = m.positions[m.triangles[c0]];
    const Vec3& p1 = m.positions[m.triangles[c0 + 1]];
    const Vec3& p2 = m.positions[m.triangles[c0 + 2]];
    const double b0 = 1.0 - b1 - b2;
    // The barycentric point is exact to a few ulps of its terms, unlike o + t*d (pbrt-v4).
    hit.p = b0 * p0 + b1 * p1 + b2 * p2;
    hit.p_error = gamma_bound(7) * (glm::abs(b0 * p0) + glm::abs(b1 * p1) + glm::abs(b2 * p2));
    hit.ng = normalize_or_facing(glm::cross(p1 - p0, p2 - p0), ray.d);
    hit.ns = hit.ng;
    if (m.normals.size() >= c0 + 3) {
        Vec3 ns = b0 * m.normals[c0] + b1 * m.normals[c0 + 1] + b2 * m.normals[c0 + 2];
        hit.ns = safe_normalize(ns, hit.ng);
        // The given normals say which side is the front.
        if (glm::dot(hit.ns, hit.ng) < 0.0) hit.ng = -hit.ng;
    }
    if (m.uvs.size() >= c0 + 3) hit.uv = b0 * m.uvs[c0] + b1 * m.uvs[c0 + 1] + b2 * m.uvs[c0 + 2];
    if (m.colors.size() >= c0 + 3) {
        hit.has_color = true;
        hit.color = b0 * m.colors[c0] + b1 * m.colors[c0 + 1] + b2 * m.colors[c0 + 2];
    }
    if (m.alphas.size() >= c0 + 3) {
        hit.has_alpha = true;
        hit.alpha = b0 * m.alphas[c0] + b1 * m.alphas[c0 + 1] + b2 * m.alphas[c0 + 2];
    }
    if (m.fog_depths.size() >= c0 + 3) {
        hit.has_fog_depth = true;
        hit.fog_depth =
            b0 * m.fog_depths[c0] + b1 * m.fog_depths[c0 + 1] + b2 * m.fog_depths[c0 + 2];
    }
    return hit;
}

}  // namespace vr
