// NURBS surfaces as faces (nurbs.h): a patch on its parameter grid, a trimmed patch cut to its
// contours, a swept surface as an Extrusion of the evaluated curves, a swung surface on the grid of
// its two curves' parameters.
#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <unordered_map>

#include "geometry/fill.h"
#include "geometry/mesh_nodes.h"
#include "geometry/nurbs.h"

namespace vr {

namespace {

// One direction of a parametric surface: its knots (for the spans the tessellation follows).
struct Direction {
    std::vector<double> knots;
    int degree = 0, count = 0, tessellation = 0;
    double start() const { return knots[size_t(degree)]; }
    double end() const { return knots[size_t(count)]; }
};
struct Parametric {
    std::function<SurfaceSample(double, double)> at;
    std::function<Vec2(double, double)> texcoord;
    Direction u, v;
    bool flip = false;  // the front is -(du x dv)
};

double net_size(const std::vector<Vec3>& points) {
    Vec3 lo(kInf), hi(-kInf);
    for (const Vec3& p : points) lo = glm::min(lo, p), hi = glm::max(hi, p);
    return points.empty() ? 0.0 : glm::length(hi - lo);
}

// Up to 65 evenly spaced parameters of a direction: the iso-curves across whose error bounds
// the other direction's sampling.
std::vector<double> probes(const Direction& d) {
    const int n = std::min(4 * (d.count - d.degree) + 1, 65);
    std::vector<double> out(size_t(std::max(n, 2)));
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = d.start() + (d.end() - d.start()) * double(i) / double(out.size() - 1);
    return out;
}

void grid_parameters(const Parametric& s, double tolerance, std::vector<double>& us,
                     std::vector<double>& vs) {
    // Half the tolerance to each direction: a cell's error is at most the sum of the two.
    const std::vector<double> across_v = probes(s.v), across_u = probes(s.u);
    us = direction_parameters(s.u.knots, s.u.degree, s.u.count, s.u.tessellation, tolerance / 2,
                              [&](double u, std::vector<Vec3>& out) {
                                  out.clear();
                                  for (double v : across_v) out.push_back(s.at(u, v).position);
                              });
    vs = direction_parameters(s.v.knots, s.v.degree, s.v.count, s.v.tessellation, tolerance / 2,
                              [&](double v, std::vector<Vec3>& out) {
                                  out.clear();
                                  for (double u : across_u) out.push_back(s.at(u, v).position);
                              });
}

// The faces under construction: a vertex per distinct (u, v), with its exact normal.
struct FaceBuilder {
    const Parametric& s;
    bool want_uvs;
    sg::IndexedFaceSet faces;
    std::unordered_map<uint64_t, int32_t> index_of;  // (u, v) bits hashed -> vertex

    int32_t vertex(double u, double v) {
        const uint64_t key =
            std::bit_cast<uint64_t>(u) * 0x9E3779B97F4A7C15ull ^ std::bit_cast<uint64_t>(v);
        if (const auto it = index_of.find(key); it != index_of.end()) {
            const Vec2 uv = uvs[size_t(it->second)];
            if (uv.x == u && uv.y == v) return it->second;
        }
        const SurfaceSample p = s.at(u, v);
        Vec3 n = glm::cross(p.du, p.dv);
        if (!(glm::length(n) > 1e-12 * glm::length(p.du) * glm::length(p.dv)) ||
            !std::isfinite(n.x)) {
            // A degenerate point (a pole, where a row of control points coincides): the normal
            // of a point a little inside the domain.
            const double eu = 1e-6 * (s.u.end() - s.u.start()),
                         ev = 1e-6 * (s.v.end() - s.v.start());
            const SurfaceSample q = s.at(u + (u < 0.5 * (s.u.start() + s.u.end()) ? eu : -eu),
                                         v + (v < 0.5 * (s.v.start() + s.v.end()) ? ev : -ev));
            n = glm::cross(q.du, q.dv);
        }
        const double length = glm::length(n);
        n = length > 0.0 && std::isfinite(length) ? n / length : Vec3(0.0);
        const int32_t index = int32_t(faces.data.coords.size());
        faces.data.coords.push_back(p.position);
        faces.data.normals.push_back(s.flip ? -n : n);
        if (want_uvs) faces.data.texcoords.push_back(s.texcoord(u, v));
        uvs.push_back(Vec2(u, v));
        index_of[key] = index;
        return index;
    }
    // A polygon counter-clockwise in (u, v).
    void face(std::initializer_list<int32_t> corners) {
        if (s.flip)
            for (auto it = std::rbegin(corners); it != std::rend(corners); ++it)
                faces.coord_index.push_back(*it);
        else
            for (int32_t c : corners) faces.coord_index.push_back(c);
        faces.coord_index.push_back(-1);
    }
    std::vector<Vec2> uvs;
};

void grid_faces(FaceBuilder& b, const std::vector<double>& us, const std::vector<double>& vs) {
    for (size_t j = 0; j + 1 < vs.size(); ++j)
        for (size_t i = 0; i + 1 < us.size(); ++i)
            b.face({b.vertex(us[i], vs[j]), b.vertex(us[i + 1], vs[j]),
                    b.vertex(us[i + 1], vs[j + 1]), b.vertex(us[i], vs[j + 1])});
}

// The part of a triangle inside the rectangle [u0,u1] x [v0,v1] (Sutherland-Hodgman: both are
// convex, so the result is one convex polygon, exact up to rounding).
std::vector<Vec2> clip_to_cell(std::vector<Vec2> poly, double u0, double u1, double v0, double v1) {
    auto clip = [&](int axis, double bound, bool keep_above) {
        std::vector<Vec2> out;
        for (size_t i = 0; i < poly.size(); ++i) {
            const Vec2 a = poly[i], b = poly[(i + 1) % poly.size()];
            const bool a_in = keep_above ? a[axis] >= bound : a[axis] <= bound;
            const bool b_in = keep_above ? b[axis] >= bound : b[axis] <= bound;
            if (a_in) out.push_back(a);
            if (a_in != b_in) {
                const double t = (bound - a[axis]) / (b[axis] - a[axis]);
                Vec2 p = a + t * (b - a);
                p[axis] = bound;  // exactly on the cell's edge, so neighbours share the vertex
                out.push_back(p);
            }
        }
        poly = std::move(out);
    };
    clip(0, u0, true);
    if (!poly.empty()) clip(0, u1, false);
    if (!poly.empty()) clip(1, v0, true);
    if (!poly.empty()) clip(1, v1, false);
    return poly;
}

// The trimmed region (X3D 27.4.10): the contours filled by the nonzero winding rule, with the
// domain's boundary added counter-clockwise when no contour runs counter-clockwise (contours that
// only cut holes), then cut along the tessellation grid so that no face spans more than a cell.
void trimmed_faces(FaceBuilder& b, const std::vector<std::vector<Vec2>>& contours,
                   const std::vector<double>& us, const std::vector<double>& vs) {
    std::vector<std::vector<Vec2>> loops = contours;
    bool any_ccw = false;
    for (const auto& c : contours) {
        double area = 0.0;
        for (size_t i = 0; i < c.size(); ++i) {
            const Vec2 p = c[i], q = c[(i + 1) % c.size()];
            area += p.x * q.y - q.x * p.y;
        }
        any_ccw = any_ccw || area > 0.0;
    }
    const double u0 = us.front(), u1 = us.back(), v0 = vs.front(), v1 = vs.back();
    if (!any_ccw) loops.push_back({{u0, v0}, {u1, v0}, {u1, v1}, {u0, v1}});
    const FlatTriangles region = fill_nonzero(loops);
    for (size_t t = 0; t + 2 < region.triangles.size(); t += 3) {
        const std::vector<Vec2> tri = {region.points[region.triangles[t]],
                                       region.points[region.triangles[t + 1]],
                                       region.points[region.triangles[t + 2]]};
        const double lo_u = std::min({tri[0].x, tri[1].x, tri[2].x});
        const double hi_u = std::max({tri[0].x, tri[1].x, tri[2].x});
        const double lo_v = std::min({tri[0].y, tri[1].y, tri[2].y});
        const double hi_v = std::max({tri[0].y, tri[1].y, tri[2].y});
        // The cells the triangle's bounding box meets.
        const size_t i0 = size_t(
            std::max<ptrdiff_t>(std::upper_bound(us.begin(), us.end(), lo_u) - us.begin() - 1, 0));
        const size_t j0 = size_t(
            std::max<ptrdiff_t>(std::upper_bound(vs.begin(), vs.end(), lo_v) - vs.begin() - 1, 0));
        for (size_t j = j0; j + 1 < vs.size() && vs[j] < hi_v; ++j)
            for (size_t i = i0; i + 1 < us.size() && us[i] < hi_u; ++i) {
                const std::vector<Vec2> piece =
                    clip_to_cell(tri, us[i], us[i + 1], vs[j], vs[j + 1]);
                if (piece.size() < 3) continue;
                const int32_t first = b.vertex(piece[0].x, piece[0].y);
                for (size_t k = 1; k + 1 < piece.size(); ++k) {
                    const Vec2 a = piece[k], c = piece[k + 1];
                    const double area = (a.x - piece[0].x) * (c.y - piece[0].y) -
                                        (c.x - piece[0].x) * (a.y - piece[0].y);
                    // Slivers the clipping makes (a triangle grazing a cell's corner) have no
                    // area the tracer could hit; dropped rather than warned about downstream.
                    if (!(area > 1e-9 * (us[i + 1] - us[i]) * (vs[j + 1] - vs[j]))) continue;
                    b.face({first, b.vertex(a.x, a.y), b.vertex(c.x, c.y)});
                }
            }
    }
}

bool make_patch(const sg::NurbsSurface& s, RationalSurface& out, NodeReport& report) {
    const int nu = s.u_dimension, nv = s.v_dimension;
    if (s.u_order < 2 || s.v_order < 2 || s.u_order > kNurbsMaxOrder ||
        s.v_order > kNurbsMaxOrder || nu < s.u_order || nv < s.v_order) {
        report.warn("order", "needs uOrder and vOrder in [2, " + std::to_string(kNurbsMaxOrder) +
                                 "] and at least that many control points each way (uDimension " +
                                 std::to_string(nu) + ", vDimension " + std::to_string(nv) +
                                 "); not drawn");
        return false;
    }
    if (s.points.size() != size_t(nu) * size_t(nv)) {
        report.warn("control-count", "has " + std::to_string(s.points.size()) +
                                         " control points for uDimension x vDimension = " +
                                         std::to_string(size_t(nu) * size_t(nv)) + "; not drawn");
        return false;
    }
    for (const Vec3& p : s.points)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            report.warn("non-finite", "has a NaN or infinite control point; not drawn");
            return false;
        }
    bool weights_ok = s.weights.empty() || s.weights.size() == s.points.size();
    for (double w : s.weights) weights_ok = weights_ok && w > 0.0 && std::isfinite(w);
    if (!weights_ok)
        report.warn("weights", "weights must be positive, one a control point; all are 1");
    out.points.resize(s.points.size());
    for (size_t i = 0; i < s.points.size(); ++i) {
        const double w = weights_ok && !s.weights.empty() ? s.weights[i] : 1.0;
        out.points[i] = Vec4(s.points[i] * w, w);
    }
    out.u_degree = s.u_order - 1, out.v_degree = s.v_order - 1;
    out.u_count = nu, out.v_count = nv;
    out.u_knots = usable_knots(s.u_knots, nu, s.u_order, report, "uKnot");
    out.v_knots = usable_knots(s.v_knots, nv, s.v_order, report, "vKnot");
    return true;
}

// Texture coordinates of a patch (X3D 27.3.3): a TextureCoordinate's points evaluated with the
// surface's own basis, a NurbsTextureCoordinate's surface at the proportional parameter, or (u, v)
// scaled to [0, 1].
std::function<Vec2(double, double)> patch_texcoords(const sg::NurbsSurface& s,
                                                    const RationalSurface& patch,
                                                    NodeReport& report) {
    const double u0 = patch.u_start(), du = patch.u_end() - patch.u_start();
    const double v0 = patch.v_start(), dv = patch.v_end() - patch.v_start();
    auto unit = [=](double u, double v) { return Vec2((u - u0) / du, (v - v0) / dv); };
    if (!s.texcoords.empty()) {
        if (s.texcoords.size() != patch.points.size()) {
            report.warn("texcoord-count",
                        "TextureCoordinate needs one point a control point; the "
                        "default mapping is used");
            return unit;
        }
        RationalSurface tex = patch;
        for (size_t i = 0; i < tex.points.size(); ++i)
            tex.points[i] = Vec4(s.texcoords[i].x, s.texcoords[i].y, 0.0, 1.0) * patch.points[i].w;
        return [tex](double u, double v) { return Vec2(evaluate(tex, u, v).position); };
    }
    if (s.texture_surface) {
        RationalSurface tex;
        if (!make_patch(*s.texture_surface, tex, report)) return unit;
        return [tex, unit](double u, double v) {
            const Vec2 f = unit(u, v);
            const double tu = tex.u_start() + f.x * (tex.u_end() - tex.u_start());
            const double tv = tex.v_start() + f.y * (tex.v_end() - tex.v_start());
            return Vec2(evaluate(tex, tu, tv).position);
        };
    }
    return unit;
}

sg::IndexedFaceSet patch_faces(const sg::NurbsSurface& s, bool want_uvs, NodeReport& report) {
    RationalSurface patch;
    if (!make_patch(s, patch, report)) return {};
    Parametric p;
    p.at = [&patch](double u, double v) { return evaluate(patch, u, v); };
    p.texcoord = patch_texcoords(s, patch, report);
    p.u = Direction{patch.u_knots, patch.u_degree, patch.u_count, s.u_tessellation};
    p.v = Direction{patch.v_knots, patch.v_degree, patch.v_count, s.v_tessellation};
    std::vector<double> us, vs;
    grid_parameters(p, kNurbsChordTolerance * net_size(s.points), us, vs);
    FaceBuilder b{p, want_uvs, {}, {}, {}};
    if (s.trimming.empty()) {
        grid_faces(b, us, vs);
    } else {
        std::vector<std::vector<Vec2>> contours;
        for (const auto& contour : s.trimming) {
            std::vector<Vec2> loop;
            for (const sg::NurbsCurve& piece : contour)
                for (const Vec3& q : curve_polyline(piece, report, "trimming curve")) {
                    const Vec2 uv(q.x, q.y);
                    if (loop.empty() || loop.back() != uv) loop.push_back(uv);
                }
            if (loop.size() >= 3) contours.push_back(std::move(loop));
        }
        trimmed_faces(b, contours, us, vs);
    }
    return std::move(b.faces);
}

sg::IndexedFaceSet swung_faces(const sg::NurbsSurface& s, bool want_uvs, NodeReport& report) {
    RationalCurve profile, trajectory;
    if (!make_curve(s.profile, profile, report, "profileCurve") ||
        !make_curve(s.trajectory, trajectory, report, "trajectoryCurve"))
        return {};
    // S(u, v) = (P.x(u) T.x(v), P.y(u), P.x(u) T.y(v)): the profile in the x-y plane turned and
    // scaled along the trajectory, a curve in the x-z plane (X3D 27.4.9).
    Parametric p;
    p.at = [&](double u, double v) {
        const CurveSample a = evaluate(profile, u), t = evaluate(trajectory, v);
        SurfaceSample out;
        out.position = Vec3(a.position.x * t.position.x, a.position.y, a.position.x * t.position.y);
        out.du = Vec3(a.derivative.x * t.position.x, a.derivative.y, a.derivative.x * t.position.y);
        out.dv = Vec3(a.position.x * t.derivative.x, 0.0, a.position.x * t.derivative.y);
        return out;
    };
    p.u = Direction{profile.knots, profile.degree, int(profile.points.size()),
                    s.profile.tessellation};
    p.v = Direction{trajectory.knots, trajectory.degree, int(trajectory.points.size()),
                    s.trajectory.tessellation};
    const double u0 = profile.start(), u1 = profile.end();
    const double v0 = trajectory.start(), v1 = trajectory.end();
    p.texcoord = [=](double u, double v) {
        return Vec2((u - u0) / (u1 - u0), (v - v0) / (v1 - v0));
    };
    p.flip = !s.ccw;
    std::vector<Vec3> net;
    for (const Vec3& a : s.profile.points)
        for (const Vec3& t : s.trajectory.points) net.push_back(Vec3(a.x * t.x, a.y, a.x * t.y));
    std::vector<double> us, vs;
    grid_parameters(p, kNurbsChordTolerance * net_size(net), us, vs);
    FaceBuilder b{p, want_uvs, {}, {}, {}};
    grid_faces(b, us, vs);
    return std::move(b.faces);
}

// NurbsSweptSurface (X3D 27.4.8): the cross section swept along the trajectory as an Extrusion
// does (its spine-aligned cross-section planes), with no caps.
sg::IndexedFaceSet swept_faces(const sg::NurbsSurface& s, bool want_uvs, NodeReport& report) {
    const std::vector<Vec3> section = curve_polyline(s.profile, report, "crossSectionCurve");
    const std::vector<Vec3> spine = curve_polyline(s.trajectory, report, "trajectoryCurve");
    if (section.size() < 2 || spine.size() < 2) return {};
    sg::Extrusion e;
    for (const Vec3& q : section) e.cross_section.push_back(Vec2(q.x, q.y));
    e.spine = spine;
    e.scale = {Vec2(1.0)};
    e.orientation = {Vec4(0.0, 0.0, 1.0, 0.0)};
    e.begin_cap = e.end_cap = false;
    e.ccw = s.ccw;
    e.solid = s.solid;
    e.convex = true;
    e.crease_angle = kPi / 2;  // smooth across the sampled curves' segments, creased at kinks
    return extrusion_faces(e, want_uvs, report);
}

}  // namespace

sg::IndexedFaceSet nurbs_surface_faces(const sg::NurbsSurface& s, bool want_uvs,
                                       NodeReport& report) {
    sg::IndexedFaceSet faces;
    switch (s.kind) {
        case sg::NurbsSurfaceKind::Patch:
            faces = patch_faces(s, want_uvs, report);
            break;
        case sg::NurbsSurfaceKind::Swung:
            faces = swung_faces(s, want_uvs, report);
            break;
        case sg::NurbsSurfaceKind::Swept:
            return swept_faces(s, want_uvs, report);
    }
    faces.ccw = true;  // the faces are wound with their normals (FaceBuilder)
    faces.solid = s.solid;
    faces.convex = true;
    faces.normal_per_vertex = true;
    faces.color_per_vertex = true;
    return faces;
}

}  // namespace vr
