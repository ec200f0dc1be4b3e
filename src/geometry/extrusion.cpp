// Extrusion (VRML97 6.18.1, X3D 13.3.5): the cross-section is scaled, rotated by `orientation`,
// placed in the spine-aligned cross-section plane (SCP) of each spine point and moved to it.
//
// SCP rules as the specification gives them:
// * Y: interior points use spine[i+1] - spine[i-1]; the ends of an open spine their own segment; a
//   closed spine (first point equals last) uses spine[1] - spine[n-2] at both ends.
// * Z: (spine[i+1] - spine[i]) x (spine[i-1] - spine[i]); the ends of an open spine copy their
//   neighbour's; a closed spine's ends use (spine[1] - spine[0]) x (spine[n-2] - spine[0]). Where
//   three points are collinear (Z = 0) the previous Z is kept (the next one at the start). Z is
//   flipped when it turns by more than 90 degrees from the previous one.
// * X = Y x Z.
// * An entirely collinear spine: the SCP is the rotation taking +Y to the spine's direction.
// * Coincident consecutive spine points share one SCP (computed on the spine with repeats removed).
// * A spine whose points all coincide: the SCP is the identity, so orientation and scale alone
//   place the cross-sections (VRML97 6.18.2's plane has no spine direction to follow).
//
// Interpretations: caps are left out for a closed spine, and where the end's scale is zero (a point
// has no cap); scale/orientation lists shorter than the spine repeat their last value (with a
// warning when their length is neither 1 nor the spine's). Side quads with no area (coincident
// spine points) are left out silently. Texture coordinates: sides s along the cross-section's
// length, t along the spine's, both 0..1; caps from the cross-section's bounding box, its larger
// side spanning 0..1.
#include <cmath>
#include <string>

#include "geometry/mesh_nodes.h"
#include "geometry/triangulate.h"
#include "scene/transform.h"

namespace vr {

namespace {

bool finite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool finite(const Vec2& v) { return std::isfinite(v.x) && std::isfinite(v.y); }

// The rotation taking the unit vector `from` onto the unit vector `to`.
Mat3 rotation_between(const Vec3& from, const Vec3& to) {
    const Vec3 axis = glm::cross(from, to);
    const double s = glm::length(axis), c = glm::dot(from, to);
    if (s < 1e-12) {
        if (c > 0.0) return Mat3(1.0);
        // Opposite: half a turn about any axis perpendicular to `from`.
        const Vec3 other = std::abs(from.x) < 0.6 ? Vec3(1, 0, 0) : Vec3(0, 0, 1);
        return rotation_matrix(glm::cross(from, other), kPi);
    }
    return rotation_matrix(axis, std::atan2(s, c));
}

// SCP axes (columns X, Y, Z) of the spine points, on a spine without consecutive repeats.
std::vector<Mat3> spine_planes(const std::vector<Vec3>& u, bool closed) {
    const size_t k = u.size();
    std::vector<Vec3> Y(k), Z(k);
    for (size_t i = 0; i < k; ++i) {
        if (closed && (i == 0 || i == k - 1)) {
            Y[i] = u[1] - u[k - 2];
            Z[i] = glm::cross(u[1] - u[0], u[k - 2] - u[0]);
        } else if (i == 0) {
            Y[i] = u[1] - u[0];
        } else if (i == k - 1) {
            Y[i] = u[k - 1] - u[k - 2];
        } else {
            Y[i] = u[i + 1] - u[i - 1];
            Z[i] = glm::cross(u[i + 1] - u[i], u[i - 1] - u[i]);
        }
    }
    if (!closed && k > 2) {
        Z[0] = Z[1];
        Z[k - 1] = Z[k - 2];
    }
    // Collinear triples give Z = 0: carry the previous (or, at the start, the next) non-zero Z.
    auto nonzero = [&](const Vec3& z, size_t i) {
        const double scale = glm::length(Y[i]) * glm::length(Y[i]);
        return glm::length(z) > 1e-12 * scale;
    };
    size_t first = k;
    for (size_t i = 0; i < k; ++i)
        if (nonzero(Z[i], i)) {
            first = i;
            break;
        }
    std::vector<Mat3> planes(k);
    if (first == k) {
        // The whole spine is collinear: one rotation from +Y to the spine's direction.
        Vec3 direction = u[k - 1] - u[0];
        if (!(glm::length(direction) > 0.0)) direction = u[1] - u[0];
        const Mat3 r = rotation_between(Vec3(0, 1, 0), glm::normalize(direction));
        for (Mat3& p : planes) p = r;
        return planes;
    }
    for (size_t i = 0; i < first; ++i) Z[i] = Z[first];
    for (size_t i = first + 1; i < k; ++i) {
        if (!nonzero(Z[i], i))
            Z[i] = Z[i - 1];
        else if (glm::dot(Z[i], Z[i - 1]) < 0.0)
            Z[i] = -Z[i];
    }
    for (size_t i = 0; i < k; ++i) {
        Vec3 y = Y[i];
        if (!(glm::length(y) > 0.0))
            y = i > 0 ? planes[i - 1][1] : Vec3(0, 1, 0);  // spine folds back on itself
        y = glm::normalize(y);
        Vec3 z = Z[i] - glm::dot(Z[i], y) * y;
        if (!(glm::length(z) > 0.0)) z = i > 0 ? planes[i - 1][2] : Vec3(0, 0, 1);
        z = glm::normalize(z);
        planes[i] = Mat3(glm::cross(y, z), y, z);
    }
    return planes;
}

// Whether a per-spine-point list holds more than one distinct value.
template <typename T>
bool varies(const std::vector<T>& values) {
    for (const T& v : values)
        if (v != values.front()) return true;
    return false;
}

// False (with a warning) when the extrusion has nothing to render; a warning too when scale or
// orientation has a count that is repeated to fit.
bool usable(const sg::Extrusion& e, NodeReport& report) {
    const size_t n = e.spine.size(), m = e.cross_section.size();
    if (n < 2 || m < 2) {
        report.warn("empty",
                    "needs at least 2 spine points and 2 crossSection points; nothing to render");
        return false;
    }
    for (const Vec3& p : e.spine)
        if (!finite(p)) {
            report.warn("non-finite", "has a NaN or infinite spine point; nothing to render");
            return false;
        }
    for (const Vec2& p : e.cross_section)
        if (!finite(p)) {
            report.warn("non-finite",
                        "has a NaN or infinite crossSection point; nothing to render");
            return false;
        }
    if ((e.scale.size() > 1 && e.scale.size() != n) ||
        (e.orientation.size() > 1 && e.orientation.size() != n))
        report.warn(
            "count",
            "scale or orientation has neither 1 nor one value a spine point; the last value "
            "is repeated");
    return true;
}

// The spine without consecutive repeats.
struct Spine {
    double tolerance = 0.0;         // "the same point" up to rounding
    std::vector<Vec3> unique;       // the points without consecutive repeats
    std::vector<size_t> unique_of;  // spine point i's place in `unique`
    bool point_spine = false;       // all spine points the same
    bool closed = false;            // first point equals last
};

Spine spine_of(const std::vector<Vec3>& points) {
    Spine spine;
    Vec3 lo(kInf), hi(-kInf);
    for (const Vec3& p : points) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    spine.tolerance = 1e-10 * glm::length(hi - lo);
    spine.unique_of.resize(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
        if (spine.unique.empty() || glm::length(points[i] - spine.unique.back()) > spine.tolerance)
            spine.unique.push_back(points[i]);
        spine.unique_of[i] = spine.unique.size() - 1;
    }
    spine.point_spine = spine.unique.size() < 2;
    spine.closed = spine.unique.size() > 2 &&
                   glm::length(spine.unique.front() - spine.unique.back()) <= spine.tolerance;
    return spine;
}

// The cross-section's bounding box, and whether it is closed (first point equals last).
struct Section {
    Vec2 lo{kInf}, hi{-kInf};
    double tolerance = 0.0;
    bool closed = false;
};

Section section_of(const std::vector<Vec2>& points) {
    Section section;
    for (const Vec2& p : points) {
        section.lo = glm::min(section.lo, p);
        section.hi = glm::max(section.hi, p);
    }
    section.tolerance = 1e-10 * glm::length(section.hi - section.lo);
    section.closed =
        points.size() > 2 && glm::length(points.front() - points.back()) <= section.tolerance;
    return section;
}

// All n x m points: cross-section j scaled, oriented and placed in spine point i's SCP.
void place_points(const sg::Extrusion& e, const Spine& spine, const std::vector<Mat3>& planes,
                  std::vector<Vec3>& coords) {
    const size_t n = e.spine.size(), m = e.cross_section.size();
    coords.resize(n * m);
    for (size_t i = 0; i < n; ++i) {
        const Vec2 s = e.scale.empty() ? Vec2(1.0) : e.scale[std::min(i, e.scale.size() - 1)];
        const Mat3 orient =
            e.orientation.empty()
                ? Mat3(1.0)
                : rotation_matrix(e.orientation[std::min(i, e.orientation.size() - 1)]);
        const Mat3 place = planes[spine.unique_of[i]] * orient;
        for (size_t j = 0; j < m; ++j) {
            const Vec2& c = e.cross_section[j];
            coords[i * m + j] = e.spine[i] + place * Vec3(c.x * s.x, 0.0, c.y * s.y);
        }
    }
}

// Each point's index: its own, except that closing rows/columns reuse the first row/column's
// index where they coincide.
std::vector<int32_t> point_index(const std::vector<Vec3>& coords, size_t n, size_t m,
                                 const Spine& spine, const Section& section) {
    std::vector<int32_t> index(n * m);
    for (size_t t = 0; t < n * m; ++t) index[t] = static_cast<int32_t>(t);
    auto same = [&](size_t a, size_t b) {
        return glm::length(coords[a] - coords[b]) <= spine.tolerance + section.tolerance;
    };
    if (section.closed)
        for (size_t i = 0; i < n; ++i)
            if (same(i * m + m - 1, i * m)) index[i * m + m - 1] = index[i * m];
    if (spine.closed)
        for (size_t j = 0; j < m; ++j)
            if (same((n - 1) * m + j, j)) index[(n - 1) * m + j] = index[j];
    return index;
}

// Texture coordinates: the side grid first, then the cap coordinates.
void add_texcoords(const sg::Extrusion& e, const Section& section, std::vector<Vec2>& texcoords) {
    const size_t n = e.spine.size(), m = e.cross_section.size();
    std::vector<double> s_of(m, 0.0), t_of(n, 0.0);
    for (size_t j = 1; j < m; ++j)
        s_of[j] = s_of[j - 1] + glm::length(e.cross_section[j] - e.cross_section[j - 1]);
    for (size_t i = 1; i < n; ++i) t_of[i] = t_of[i - 1] + glm::length(e.spine[i] - e.spine[i - 1]);
    for (double& s : s_of) s = s_of.back() > 0.0 ? s / s_of.back() : 0.0;
    // A spine of one point: t by the spine point's number instead of its length.
    for (size_t i = 0; i < n; ++i)
        t_of[i] = t_of.back() > 0.0 ? t_of[i] / t_of.back() : double(i) / double(n - 1);
    texcoords.reserve(n * m + m);
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < m; ++j) texcoords.push_back(Vec2(s_of[j], t_of[i]));
    const double size = std::max(section.hi.x - section.lo.x, section.hi.y - section.lo.y);
    for (size_t j = 0; j < m; ++j)
        texcoords.push_back(size > 0.0 ? (e.cross_section[j] - section.lo) / size : Vec2(0.0));
}

// The side quads (those with area) and the caps, as faces of `index`.
void add_faces(const sg::Extrusion& e, const std::vector<int32_t>& index, bool closed_spine,
               bool closed_section, bool want_uvs, sg::IndexedFaceSet& faces) {
    const size_t n = e.spine.size(), m = e.cross_section.size();
    const std::vector<Vec3>& coords = faces.data.coords;
    auto add_corner = [&](size_t point, int32_t uv) {
        faces.coord_index.push_back(index[point]);
        if (want_uvs) faces.texcoord_index.push_back(uv);
    };
    auto end_face = [&] {
        faces.coord_index.push_back(-1);
        if (want_uvs) faces.texcoord_index.push_back(-1);
    };

    Vec3 quad[4];
    for (size_t i = 0; i + 1 < n; ++i)
        for (size_t j = 0; j + 1 < m; ++j) {
            const size_t corners[4] = {i * m + j, i * m + j + 1, (i + 1) * m + j + 1,
                                       (i + 1) * m + j};
            for (int c = 0; c < 4; ++c) quad[c] = coords[corners[c]];
            const Vec3 normal = newell_normal(quad);
            const double extent = glm::length(quad[2] - quad[0]) + glm::length(quad[3] - quad[1]);
            if (!(glm::length(normal) > 1e-12 * extent * extent))
                continue;  // coincident spine points
            for (size_t c : corners) add_corner(c, static_cast<int32_t>(c));
            end_face();
        }

    const size_t cap_points = closed_section ? m - 1 : m;
    const int32_t cap_uv = static_cast<int32_t>(n * m);
    auto scale_at = [&](size_t i) {
        return e.scale.empty() ? Vec2(1.0) : e.scale[std::min(i, e.scale.size() - 1)];
    };
    if (!closed_spine && cap_points >= 3) {
        const Vec2 s0 = scale_at(0), s1 = scale_at(n - 1);
        if (e.begin_cap && s0.x != 0.0 && s0.y != 0.0) {
            // Faces away from the spine's direction: the cross-section's order reversed.
            for (size_t j = cap_points; j-- > 0;) add_corner(j, cap_uv + static_cast<int32_t>(j));
            end_face();
        }
        if (e.end_cap && s1.x != 0.0 && s1.y != 0.0) {
            for (size_t j = 0; j < cap_points; ++j)
                add_corner((n - 1) * m + j, cap_uv + static_cast<int32_t>(j));
            end_face();
        }
    }
}

}  // namespace

sg::IndexedFaceSet extrusion_faces(const sg::Extrusion& e, bool want_uvs, NodeReport& report) {
    sg::IndexedFaceSet faces;
    faces.ccw = e.ccw;
    faces.solid = e.solid;
    faces.convex = e.convex;
    faces.crease_angle = e.crease_angle;
    if (!usable(e, report)) return faces;
    const Spine spine = spine_of(e.spine);
    // All spine points the same: the SCP is the identity (no direction to align to), and the
    // shape, if any, comes from orientation and scale alone (cobweb's HalfSpheres turn one
    // cross-section about the point).
    if (spine.point_spine && !varies(e.scale) && !varies(e.orientation)) {
        report.warn("zero-size",
                    "all spine points coincide and scale and orientation do not change; nothing "
                    "to render");
        return faces;
    }
    const std::vector<Mat3> planes =
        spine.point_spine ? std::vector<Mat3>{Mat3(1.0)} : spine_planes(spine.unique, spine.closed);
    const Section section = section_of(e.cross_section);
    place_points(e, spine, planes, faces.data.coords);
    const std::vector<int32_t> index =
        point_index(faces.data.coords, e.spine.size(), e.cross_section.size(), spine, section);
    if (want_uvs) add_texcoords(e, section, faces.data.texcoords);
    add_faces(e, index, spine.closed, section.closed, want_uvs, faces);
    return faces;
}

}  // namespace vr
