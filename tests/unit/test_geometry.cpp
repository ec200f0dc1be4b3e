// Polygon geometry -> triangles: ear clipping, IndexedFaceSet rules, ElevationGrid, Extrusion, X3D
// sets.
#include <gtest/gtest.h>

#include <cmath>

#include "geometry/mesh_nodes.h"
#include "geometry/polygon_mesh.h"
#include "geometry/triangulate.h"
#include "scene/transform.h"

namespace vr {
namespace {

// Areas and coordinates here are sums of a few exact binary fractions; 1e-12 only absorbs the
// rounding of the projections onto the polygon plane.
constexpr double kTight = 1e-12;

sg::Origin test_origin(std::string_view type) {
    sg::Origin o;
    o.type = intern(type);
    return o;
}

struct FaceSetRun {
    Diagnostics diagnostics;
    sg::Origin origin;
    explicit FaceSetRun(std::string_view type) : origin(test_origin(type)) {}
    TriMesh faces(const sg::IndexedFaceSet& f, bool uvs = false) {
        NodeReport report(diagnostics, origin);
        return triangulate_face_set(f, uvs, report);
    }
};

double triangle_area(std::span<const Vec3> p, const uint32_t* t) {
    return 0.5 * glm::length(glm::cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]));
}

// The typed structs start neutral (scene.h): these give the flags the specifications default to
// (VRML97 6.23, 6.17, 6.18; X3D 11.4), as the scene build reads them from the grammar.
sg::IndexedFaceSet face_set() {
    sg::IndexedFaceSet f;
    f.ccw = f.solid = f.convex = f.color_per_vertex = f.normal_per_vertex = true;
    return f;
}
sg::Extrusion extrusion() {
    sg::Extrusion e;
    e.begin_cap = e.end_cap = e.ccw = e.solid = e.convex = true;
    return e;
}
sg::ElevationGrid elevation_grid() {
    sg::ElevationGrid g;
    g.ccw = g.solid = g.color_per_vertex = g.normal_per_vertex = true;
    return g;
}
sg::ComposedSet composed_set(sg::ComposedKind kind) {
    sg::ComposedSet c;
    c.kind = kind;
    c.ccw = c.solid = c.color_per_vertex = c.normal_per_vertex = true;
    return c;
}

TEST(Geometry, EarClippingConcaveLShape) {
    // An L of area 3, in a tilted plane so the projection matters.
    const Mat3 tilt = rotation_matrix(Vec3(1, 2, 3), 0.7);
    std::vector<Vec3> points;
    for (const Vec2& p : {Vec2(0, 0), Vec2(2, 0), Vec2(2, 1), Vec2(1, 1), Vec2(1, 2), Vec2(0, 2)})
        points.push_back(tilt * Vec3(p, 0.0) + Vec3(100, -50, 7));
    std::vector<uint32_t> triangles;
    ASSERT_TRUE(triangulate_polygon(points, triangles));
    // At most n - 2 triangles: fewer when the ears leave three collinear vertices (no area) at the
    // end.
    ASSERT_GE(triangles.size(), 9u);
    ASSERT_LE(triangles.size(), 12u);
    double area = 0.0;
    const Vec3 normal = glm::normalize(newell_normal(points));
    for (size_t t = 0; t < triangles.size(); t += 3) {
        area += triangle_area(points, &triangles[t]);
        // Every triangle keeps the polygon's orientation.
        const Vec3 n = glm::cross(points[triangles[t + 1]] - points[triangles[t]],
                                  points[triangles[t + 2]] - points[triangles[t]]);
        EXPECT_GT(glm::dot(n, normal), 0.0);
    }
    // Coordinates near 100 carry rounding of about 1e-14 each.
    EXPECT_NEAR(area, 3.0, 1e-10);
}

TEST(Geometry, DegeneratePolygonsHaveNoTriangles) {
    std::vector<uint32_t> out;
    const std::vector<Vec3> line = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0)};
    EXPECT_FALSE(triangulate_polygon(line, out));
    const std::vector<Vec3> repeated = {Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0)};
    EXPECT_FALSE(triangulate_polygon(repeated, out));
    const std::vector<Vec3> nan = {Vec3(0, 0, 0), Vec3(std::nan(""), 0, 0), Vec3(1, 1, 0)};
    EXPECT_FALSE(triangulate_polygon(nan, out));
    EXPECT_TRUE(out.empty());
}

TEST(Geometry, IndexedFaceSetConcaveLArea) {
    sg::IndexedFaceSet f = face_set();
    f.data.coords = {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(2, 1, 0),
                     Vec3(1, 1, 0), Vec3(1, 2, 0), Vec3(0, 2, 0)};
    f.coord_index = {0, 1, 2, 3, 4, 5, -1};
    FaceSetRun run("IndexedFaceSet");
    const TriMesh mesh = run.faces(f);
    EXPECT_LE(mesh.triangle_count(), 4u);
    EXPECT_NEAR(mesh.area(), 3.0, kTight);
    EXPECT_TRUE(mesh.normals.empty());  // creaseAngle 0: flat
    EXPECT_EQ(run.diagnostics.warning_count(), 0u);

    // ccw FALSE reverses the winding: the triangles then face -Z.
    f.ccw = false;
    const TriMesh reversed = run.faces(f);
    for (size_t t = 0; t < reversed.triangles.size(); t += 3) {
        const auto& p = reversed.positions;
        const uint32_t* c = &reversed.triangles[t];
        EXPECT_LT(glm::cross(p[c[1]] - p[c[0]], p[c[2]] - p[c[0]]).z, 0.0);
    }
}

TEST(Geometry, IndexedFaceSetSkipsBadFacesAndWarnsOnce) {
    sg::IndexedFaceSet f = face_set();
    f.data.coords = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0), Vec3(NAN, 0, 0)};
    f.coord_index = {0, 1, 2, -1, 0, 2, 9, -1, 0, 2, 4, -1, 0, 1, -1, 0, 2, 3};
    FaceSetRun run("IndexedFaceSet");
    const TriMesh mesh = run.faces(f);
    EXPECT_EQ(mesh.triangle_count(), 2u);  // the first and the last (no trailing -1) faces
    // Out of range, non-finite, too few vertices: three causes, one warning each.
    EXPECT_EQ(run.diagnostics.warning_count(), 3u);
    for (const Vec3& p : mesh.positions) EXPECT_TRUE(std::isfinite(p.x));
}

// A unit cube as six quads, outward.
sg::IndexedFaceSet cube() {
    sg::IndexedFaceSet f = face_set();
    for (int i = 0; i < 8; ++i)
        f.data.coords.push_back(Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1) - Vec3(0.5));
    f.coord_index = {0, 2, 3, 1, -1, 4, 5, 7, 6, -1, 0, 1, 5, 4, -1,
                     2, 6, 7, 3, -1, 0, 4, 6, 2, -1, 1, 3, 7, 5, -1};
    return f;
}

TEST(Geometry, CreaseAngleZeroIsFlatAndPiIsSmooth) {
    sg::IndexedFaceSet f = cube();
    FaceSetRun run("IndexedFaceSet");
    const TriMesh flat = run.faces(f);
    EXPECT_EQ(flat.triangle_count(), 12u);
    EXPECT_NEAR(flat.area(), 6.0, kTight);
    EXPECT_TRUE(flat.normals.empty());
    // Flat faces all point outwards.
    for (size_t t = 0; t < flat.triangles.size(); t += 3) {
        const auto& p = flat.positions;
        const uint32_t* c = &flat.triangles[t];
        const Vec3 n = glm::cross(p[c[1]] - p[c[0]], p[c[2]] - p[c[0]]);
        EXPECT_GT(glm::dot(n, (p[c[0]] + p[c[1]] + p[c[2]]) / 3.0), 0.0);
    }

    f.crease_angle = kPi;  // every face around a corner (they meet at 90 degrees)
    const TriMesh smooth = run.faces(f);
    ASSERT_EQ(smooth.normals.size(), smooth.triangles.size());
    for (size_t c = 0; c < smooth.triangles.size(); ++c) {
        const Vec3 corner = smooth.positions[smooth.triangles[c]];
        // The mean of three perpendicular unit normals: the corner's diagonal.
        const Vec3 expected = glm::normalize(corner);
        EXPECT_NEAR(glm::length(smooth.normals[c] - expected), 0.0, kTight);
    }

    f.crease_angle = 1.5;  // just below 90 degrees: the faces stay apart
    const TriMesh creased = run.faces(f);
    ASSERT_EQ(creased.normals.size(), creased.triangles.size());
    for (size_t c = 0; c < creased.triangles.size(); ++c) {
        const Vec3 n = creased.normals[c];
        EXPECT_NEAR(std::abs(n.x) + std::abs(n.y) + std::abs(n.z), 1.0, kTight);  // an axis
    }
}

TEST(Geometry, ExplicitNormalsColorsAndIndices) {
    sg::IndexedFaceSet f = face_set();
    f.data.coords = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    f.coord_index = {0, 1, 2, -1, 0, 2, 3, -1};
    f.data.normals = {Vec3(0, 0, 2), Vec3(0, 1, 1)};
    f.normal_per_vertex = false;  // one a face, in order
    f.data.colors = {Vec3(1, 0, 0), Vec3(0, 1, 0)};
    f.color_per_vertex = false;
    f.color_index = {1, 0};
    FaceSetRun run("IndexedFaceSet");
    const TriMesh mesh = run.faces(f);
    ASSERT_EQ(mesh.triangle_count(), 2u);
    ASSERT_EQ(mesh.normals.size(), 6u);
    EXPECT_EQ(mesh.normals[0], Vec3(0, 0, 1));  // normalised
    EXPECT_NEAR(mesh.normals[3].y, std::sqrt(0.5), kTight);
    EXPECT_EQ(mesh.colors[0], Vec3(0, 1, 0));
    EXPECT_EQ(mesh.colors[5], Vec3(1, 0, 0));

    f.color_index = {1, 7};  // out of range: colours dropped, normals kept
    const TriMesh dropped = run.faces(f);
    EXPECT_TRUE(dropped.colors.empty());
    EXPECT_EQ(dropped.normals.size(), 6u);
    EXPECT_EQ(run.diagnostics.warning_count(), 1u);
}

TEST(Geometry, DefaultTextureMappingUsesTwoLargestDimensions) {
    // A 4 x 2 rectangle in the XZ plane: s along X (0..1), t along Z (0..0.5: divided by the larger
    // size).
    sg::IndexedFaceSet f = face_set();
    f.data.coords = {Vec3(0, 0, 0), Vec3(0, 0, 2), Vec3(4, 0, 2), Vec3(4, 0, 0)};
    f.coord_index = {0, 1, 2, 3, -1};
    FaceSetRun run("IndexedFaceSet");
    const TriMesh mesh = run.faces(f, true);
    ASSERT_EQ(mesh.uvs.size(), mesh.triangles.size());
    for (size_t c = 0; c < mesh.triangles.size(); ++c) {
        const Vec3 p = mesh.positions[mesh.triangles[c]];
        EXPECT_NEAR(mesh.uvs[c].x, p.x / 4.0, kTight);
        EXPECT_NEAR(mesh.uvs[c].y, p.z / 4.0, kTight);
    }
    // Ties go X, then Y, then Z: a square in YZ maps s to Y, t to Z.
    const DefaultTexMapping m = DefaultTexMapping::from_bounds(Vec3(0), Vec3(0, 2, 2));
    EXPECT_EQ(m.s_axis, 1);
    EXPECT_EQ(m.t_axis, 2);
}

TEST(Geometry, ExtrusionOfASquareAlongAStraightSpineIsABox) {
    sg::Extrusion e =
        extrusion();  // the specification's defaults: a 2 x 2 square along 0 0 0 -> 0 1 0
    e.cross_section = {Vec2(1, 1), Vec2(1, -1), Vec2(-1, -1), Vec2(-1, 1), Vec2(1, 1)};
    e.spine = {Vec3(0, 0, 0), Vec3(0, 1, 0)};
    e.scale = {Vec2(1, 1)};
    e.orientation = {Vec4(0, 0, 1, 0)};
    Diagnostics diagnostics;
    const sg::Origin origin = test_origin("Extrusion");
    NodeReport report(diagnostics, origin);
    const TriMesh mesh = triangulate_face_set(extrusion_faces(e, false, report), false, report);
    // 2 x 1 x 2 box: two 2x2 caps and four 2x1 sides.
    EXPECT_NEAR(mesh.area(), 16.0, kTight);
    EXPECT_EQ(mesh.triangle_count(), 12u);
    // Every face points away from the box's centre (0, 0.5, 0).
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        const auto& p = mesh.positions;
        const uint32_t* c = &mesh.triangles[t];
        const Vec3 n = glm::cross(p[c[1]] - p[c[0]], p[c[2]] - p[c[0]]);
        EXPECT_GT(glm::dot(n, (p[c[0]] + p[c[1]] + p[c[2]]) / 3.0 - Vec3(0, 0.5, 0)), 0.0)
            << "triangle " << t / 3;
    }
    EXPECT_EQ(diagnostics.warning_count(), 0u);

    // The same box along a spine with a repeated point and a scale: coincident points share an SCP.
    e.spine = {Vec3(0, 0, 0), Vec3(0, 0.5, 0), Vec3(0, 0.5, 0), Vec3(0, 1, 0)};
    e.scale = {Vec2(0.5, 0.5)};
    const TriMesh scaled = triangulate_face_set(extrusion_faces(e, false, report), false, report);
    EXPECT_NEAR(scaled.area(), 2 * 1.0 + 4 * 1.0, kTight);
}

TEST(Geometry, ExtrusionAroundABendKeepsCrossSectionArea) {
    // A circle-ish hexagon swept along a quarter circle; each cap's area equals the hexagon's.
    sg::Extrusion e = extrusion();
    for (int k = 0; k <= 6; ++k)
        e.cross_section.push_back(Vec2(std::cos(-k * kPi / 3), std::sin(-k * kPi / 3)));
    for (int k = 0; k <= 8; ++k)
        e.spine.push_back(Vec3(10 * (1 - std::cos(k * kPi / 16)), 10 * std::sin(k * kPi / 16), 0));
    e.scale = {Vec2(1, 1)};
    e.orientation = {Vec4(0, 0, 1, 0)};
    e.begin_cap = e.end_cap = false;
    Diagnostics diagnostics;
    const sg::Origin origin = test_origin("Extrusion");
    NodeReport report(diagnostics, origin);
    const TriMesh sides = triangulate_face_set(extrusion_faces(e, false, report), false, report);
    EXPECT_EQ(sides.triangle_count(), 8u * 6u * 2u);
    e.begin_cap = e.end_cap = true;
    const TriMesh all = triangulate_face_set(extrusion_faces(e, false, report), false, report);
    const double hexagon = 3.0 * std::sqrt(3.0) / 2.0;
    // Caps are exact hexagons; only rounding of sin/cos remains.
    EXPECT_NEAR(all.area() - sides.area(), 2 * hexagon, 1e-9);
    EXPECT_EQ(diagnostics.warning_count(), 0u);
}

TEST(Geometry, ElevationGridTriangleCountAndArea) {
    sg::ElevationGrid g = elevation_grid();
    g.x_dimension = 4;
    g.z_dimension = 3;
    g.x_spacing = 0.5;
    g.z_spacing = 2.0;
    g.height.assign(12, 1.0);
    Diagnostics diagnostics;
    const sg::Origin origin = test_origin("ElevationGrid");
    NodeReport report(diagnostics, origin);
    const TriMesh mesh = triangulate_face_set(elevation_grid_faces(g, true, report), true, report);
    EXPECT_EQ(mesh.triangle_count(), 3u * 2u * 2u);
    EXPECT_NEAR(mesh.area(), 1.5 * 4.0, kTight);
    // Front faces up; default texture coordinates span 0..1 over the grid.
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        const auto& p = mesh.positions;
        const uint32_t* c = &mesh.triangles[t];
        EXPECT_GT(glm::cross(p[c[1]] - p[c[0]], p[c[2]] - p[c[0]]).y, 0.0);
    }
    for (size_t c = 0; c < mesh.uvs.size(); ++c) {
        const Vec3 p = mesh.positions[mesh.triangles[c]];
        EXPECT_NEAR(mesh.uvs[c].x, p.x / 1.5, kTight);
        EXPECT_NEAR(mesh.uvs[c].y, p.z / 4.0, kTight);
    }
    g.height.resize(5);  // too few heights: nothing, one warning
    EXPECT_TRUE(elevation_grid_faces(g, false, report).coord_index.empty());
    EXPECT_EQ(diagnostics.warning_count(), 1u);
}

TEST(Geometry, X3DTriangleAndQuadSets) {
    Diagnostics diagnostics;
    const sg::Origin origin = test_origin("TriangleStripSet");
    NodeReport report(diagnostics, origin);
    sg::ComposedSet strip = composed_set(sg::ComposedKind::TriangleStripSet);
    strip.data.coords = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(0, 2, 0)};
    strip.counts = {5};
    const TriMesh s = triangulate_face_set(composed_faces(strip, report), false, report);
    EXPECT_EQ(s.triangle_count(), 3u);
    EXPECT_NEAR(s.area(), 1.5, kTight);
    // Strips alternate their winding in the input; the output keeps the first triangle's
    // orientation.
    const double first = glm::cross(s.positions[s.triangles[1]] - s.positions[s.triangles[0]],
                                    s.positions[s.triangles[2]] - s.positions[s.triangles[0]])
                             .z;
    for (size_t t = 0; t < s.triangles.size(); t += 3) {
        const auto& p = s.positions;
        const uint32_t* c = &s.triangles[t];
        EXPECT_GT(glm::cross(p[c[1]] - p[c[0]], p[c[2]] - p[c[0]]).z * first, 0.0);
    }

    sg::ComposedSet fan = composed_set(sg::ComposedKind::IndexedTriangleFanSet);
    fan.data.coords = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    fan.index = {0, 1, 2, 3, -1};
    const TriMesh f = triangulate_face_set(composed_faces(fan, report), false, report);
    EXPECT_EQ(f.triangle_count(), 2u);
    EXPECT_NEAR(f.area(), 1.0, kTight);
    // normalPerVertex TRUE without normals: averaged over the triangles sharing a vertex (all
    // coplanar).
    ASSERT_EQ(f.normals.size(), 6u);
    for (const Vec3& n : f.normals) EXPECT_NEAR(n.z, 1.0, kTight);

    sg::ComposedSet quads = composed_set(sg::ComposedKind::QuadSet);
    quads.data.coords = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0),
                         Vec3(0, 1, 0), Vec3(5, 5, 5), Vec3(6, 6, 6)};
    const TriMesh q = triangulate_face_set(composed_faces(quads, report), false, report);
    EXPECT_EQ(q.triangle_count(), 2u);  // the two extra coordinates are ignored
    EXPECT_EQ(diagnostics.warning_count(), 0u);
}

}  // namespace
}  // namespace vr
