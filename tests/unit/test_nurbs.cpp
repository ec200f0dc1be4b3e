// NURBS (src/geometry/nurbs.h): de Boor's algorithm against values worked out by hand, exact
// circles from rational curves, the tessellation's chordal error bound, trimming holes.
#include <gtest/gtest.h>

#include <cmath>

#include "geometry/lines.h"
#include "geometry/mesh_nodes.h"
#include "geometry/nurbs.h"
#include "geometry/polygon_mesh.h"

namespace vr {
namespace {

const double kHalfRoot2 = std::sqrt(0.5);

struct NurbsRun {
    Diagnostics diagnostics;
    sg::Origin origin;
    NurbsRun() { origin.type = intern("NurbsPatchSurface"); }
    NodeReport report() { return NodeReport(diagnostics, origin); }
};

// The quarter circle from (1,0) to (0,1): a rational quadratic with the middle weight cos(45 deg).
sg::NurbsCurve quarter_circle() {
    sg::NurbsCurve c;
    c.points = {Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
    c.weights = {1.0, kHalfRoot2, 1.0};
    c.knots = {0, 0, 0, 1, 1, 1};
    c.order = 3;
    return c;
}

// The full unit circle in the x-y plane: four quarter circles, 9 points, knots doubled at the
// joins.
sg::NurbsCurve full_circle(double radius = 1.0) {
    sg::NurbsCurve c;
    const double r = radius;
    c.points = {Vec3(r, 0, 0),   Vec3(r, r, 0),  Vec3(0, r, 0),  Vec3(-r, r, 0), Vec3(-r, 0, 0),
                Vec3(-r, -r, 0), Vec3(0, -r, 0), Vec3(r, -r, 0), Vec3(r, 0, 0)};
    c.weights = {1, kHalfRoot2, 1, kHalfRoot2, 1, kHalfRoot2, 1, kHalfRoot2, 1};
    c.knots = {0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4};
    c.order = 3;
    return c;
}

TEST(Nurbs, QuarterCircleMidpointAndTangentByHand) {
    NurbsRun run;
    NodeReport report = run.report();
    RationalCurve curve;
    ASSERT_TRUE(make_curve(quarter_circle(), curve, report, "curve"));
    // By hand: the basis at t = 1/2 is (1/4, 1/2, 1/4); the homogeneous point is
    // ((1 + sqrt2)/4, (1 + sqrt2)/4, w = (2 + sqrt2)/4), so C = (1/sqrt2, 1/sqrt2).
    const CurveSample mid = evaluate(curve, 0.5);
    EXPECT_NEAR(mid.position.x, kHalfRoot2, 1e-15);
    EXPECT_NEAR(mid.position.y, kHalfRoot2, 1e-15);
    // At t = 0: A' = 2 (w1 P1 - w0 P0) = (sqrt2 - 2, sqrt2), w' = sqrt2 - 2, so
    // C' = A' - w' C = (0, sqrt2).
    const CurveSample start = evaluate(curve, 0.0);
    EXPECT_NEAR(start.derivative.x, 0.0, 1e-15);
    EXPECT_NEAR(start.derivative.y, std::sqrt(2.0), 1e-15);
    // Every point lies on the unit circle (the rational form is exact, not an approximation),
    // and the derivative is tangent to it.
    for (int i = 0; i <= 100; ++i) {
        const CurveSample s = evaluate(curve, i / 100.0);
        EXPECT_NEAR(glm::length(s.position), 1.0, 1e-15) << i;
        EXPECT_NEAR(glm::dot(s.position, s.derivative), 0.0, 1e-14) << i;
    }
}

TEST(Nurbs, DeBoorOnAnInteriorKnotByHand) {
    // Degree 2, knots 0 0 0 .5 1 1 1, t = 1/4 in span [0, .5): de Boor's first level gives
    // d1 = (P0 + P1)/2 (alpha 1/2), d2 = 3/4 P1 + 1/4 P2 (alpha 1/4); the second (alpha 1/2)
    // 1/4 P0 + 5/8 P1 + 1/8 P2 = (1, 1.5) for P = (0,0), (1,2), (3,2), (4,0).
    sg::NurbsCurve c;
    c.points = {Vec3(0, 0, 0), Vec3(1, 2, 0), Vec3(3, 2, 0), Vec3(4, 0, 0)};
    c.knots = {0, 0, 0, 0.5, 1, 1, 1};
    c.order = 3;
    NurbsRun run;
    NodeReport report = run.report();
    RationalCurve curve;
    ASSERT_TRUE(make_curve(c, curve, report, "curve"));
    const CurveSample s = evaluate(curve, 0.25);
    EXPECT_DOUBLE_EQ(s.position.x, 1.0);
    EXPECT_DOUBLE_EQ(s.position.y, 1.5);
    // Derivative: 2 (d2 - d1) / (.5 - 0) from the first level's points d1 = (0.5, 1), d2 = (1.5,
    // 2), so (4, 4); the same as the basis derivatives on [0, .5): N0 = (1 - 2t)^2, N1 = 4t - 6t^2,
    // N2 = 2t^2 give C' = -2 P0 + P1 + P2 at t = 1/4.
    EXPECT_DOUBLE_EQ(s.derivative.x, 4.0);
    EXPECT_DOUBLE_EQ(s.derivative.y, 4.0);
    // The ends are the end points (clamped knots).
    EXPECT_EQ(evaluate(curve, 1.0).position, Vec3(4, 0, 0));
    EXPECT_EQ(evaluate(curve, 0.0).position, Vec3(0, 0, 0));
}

sg::NurbsSurface bilinear() {
    sg::NurbsSurface s;
    s.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 1)};
    s.u_order = s.v_order = 2;
    s.u_dimension = s.v_dimension = 2;
    s.u_knots = s.v_knots = {0, 0, 1, 1};
    s.solid = true;
    return s;
}

TEST(Nurbs, BilinearPatchIsUVAndUTimesV) {
    NurbsRun run;
    NodeReport report = run.report();
    sg::NurbsSurface s = bilinear();
    s.u_tessellation = 4;
    s.v_tessellation = 2;
    const sg::IndexedFaceSet faces = nurbs_surface_faces(s, true, report);
    // X3D's rule for a positive tessellation: that many segments, so 5 x 3 vertices, 8 quads.
    ASSERT_EQ(faces.data.coords.size(), 15u);
    EXPECT_EQ(std::count(faces.coord_index.begin(), faces.coord_index.end(), -1), 8);
    for (size_t i = 0; i < faces.data.coords.size(); ++i) {
        const Vec3 p = faces.data.coords[i];
        // S(u, v) = (u, v, u v); the normal S_u x S_v = (1, 0, v) x (0, 1, u) = (-v, -u, 1).
        EXPECT_NEAR(p.z, p.x * p.y, 1e-15);
        const Vec3 n = glm::normalize(Vec3(-p.y, -p.x, 1.0));
        EXPECT_NEAR(glm::distance(faces.data.normals[i], n), 0.0, 1e-15);
        EXPECT_EQ(faces.data.texcoords[i], Vec2(p.x, p.y));  // the default: (u, v) on [0,1]
    }
    EXPECT_TRUE(run.diagnostics.warning_count() == 0) << run.diagnostics.warning_count();
}

// A quarter cylinder of radius 1 about the y axis: u the rational quarter circle in x-z, v the
// height 0..2. Checks the default tessellation's chordal bound (nurbs.h): every edge midpoint lies
// within kNurbsChordTolerance x the net's diagonal of the cylinder.
TEST(Nurbs, RationalCylinderDefaultTessellationKeepsItsChordalBound) {
    sg::NurbsSurface s;
    const Vec3 arc[3] = {Vec3(1, 0, 0), Vec3(1, 0, -1), Vec3(0, 0, -1)};
    for (int j = 0; j < 2; ++j)
        for (const Vec3& a : arc) s.points.push_back(a + Vec3(0, 2.0 * j, 0));
    s.weights = {1, kHalfRoot2, 1, 1, kHalfRoot2, 1};
    s.u_order = 3, s.v_order = 2, s.u_dimension = 3, s.v_dimension = 2;
    s.u_knots = {0, 0, 0, 1, 1, 1};
    s.v_knots = {0, 0, 1, 1};
    NurbsRun run;
    NodeReport report = run.report();
    const sg::IndexedFaceSet faces = nurbs_surface_faces(s, false, report);
    ASSERT_FALSE(faces.data.coords.empty());
    const double tolerance = kNurbsChordTolerance * std::sqrt(1 + 1 + 4);
    auto radius = [](const Vec3& p) { return std::hypot(p.x, p.z); };
    for (size_t i = 0; i < faces.data.coords.size(); ++i) {
        EXPECT_NEAR(radius(faces.data.coords[i]), 1.0, 1e-15);
        const Vec3 p = faces.data.coords[i], n = faces.data.normals[i];
        // S_u x S_v points away from the axis (u turns from +x towards -z, v goes up).
        EXPECT_NEAR(glm::distance(n, Vec3(p.x, 0, p.z)), 0.0, 1e-14);
    }
    double worst = 0.0;
    size_t corners = 0;
    for (size_t start = 0; start < faces.coord_index.size(); start += corners + 1) {
        corners = 0;
        while (faces.coord_index[start + corners] >= 0) ++corners;
        for (size_t k = 0; k < corners; ++k) {
            const Vec3 a = faces.data.coords[size_t(faces.coord_index[start + k])];
            const Vec3 b = faces.data.coords[size_t(faces.coord_index[start + (k + 1) % corners])];
            worst = std::max(worst, 1.0 - radius(0.5 * (a + b)));
        }
    }
    EXPECT_LE(worst, tolerance);
    EXPECT_GT(worst, tolerance / 8);  // and not wastefully finer (a quarter of the segments)
}

double area_of(const TriMesh& mesh) { return mesh.area(); }

TriMesh trimmed(const std::vector<std::vector<sg::NurbsCurve>>& contours, NurbsRun& run) {
    sg::NurbsSurface s = bilinear();
    s.points[3] = Vec3(1, 1, 0);  // flat: area in (u, v) is area in space
    s.trimming = contours;
    NodeReport report = run.report();
    const sg::IndexedFaceSet faces = nurbs_surface_faces(s, false, report);
    return triangulate_face_set(faces, false, report);
}

sg::NurbsCurve polyline(std::vector<Vec2> points) {
    sg::NurbsCurve c;
    c.polyline = true;
    for (const Vec2& p : points) c.points.push_back(Vec3(p, 0.0));
    return c;
}

TEST(Nurbs, TrimmedPatchHasItsHole) {
    NurbsRun run;
    // One clockwise square: a hole in the whole domain (the boundary is implied).
    const sg::NurbsCurve hole =
        polyline({{0.25, 0.25}, {0.25, 0.75}, {0.75, 0.75}, {0.75, 0.25}, {0.25, 0.25}});
    const TriMesh mesh = trimmed({{hole}}, run);
    EXPECT_NEAR(area_of(mesh), 1.0 - 0.25, 1e-12);
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        const Vec3 c = (mesh.positions[mesh.triangles[t]] + mesh.positions[mesh.triangles[t + 1]] +
                        mesh.positions[mesh.triangles[t + 2]]) /
                       3.0;
        EXPECT_FALSE(c.x > 0.25 && c.x < 0.75 && c.y > 0.25 && c.y < 0.75) << c.x << " " << c.y;
    }
    // A counter-clockwise outline keeps its inside; with the hole, a ring.
    const sg::NurbsCurve outline = polyline({{0.1, 0.1}, {0.9, 0.1}, {0.9, 0.9}, {0.1, 0.9}});
    EXPECT_NEAR(area_of(trimmed({{outline}}, run)), 0.64, 1e-12);
    EXPECT_NEAR(area_of(trimmed({{outline}, {hole}}, run)), 0.64 - 0.25, 1e-12);
    // A round hole from a NurbsCurve2D circle of radius 0.25 about (0.5, 0.5), traversed clockwise
    // by mirroring y: the hole is the circle less the chords' segments, at most the perimeter
    // (pi / 2) times the curve's chordal bound (kNurbsChordTolerance x its net's diagonal,
    // 0.5 sqrt 2), 2.8e-3 of the circle's area.
    sg::NurbsCurve circle = full_circle(0.25);
    for (Vec3& p : circle.points) p = Vec3(0.5 + p.x, 0.5 - p.y, 0.0);
    const double round = area_of(trimmed({{circle}}, run));
    EXPECT_NEAR(round, 1.0 - kPi / 16, kPi / 2 * kNurbsChordTolerance * std::sqrt(0.5));
    EXPECT_GT(round, 1.0 - kPi / 16);  // chords cut inside the circle: the hole is a bit smaller
}

TEST(Nurbs, SwungSurfaceOfALineAboutACircleIsACylinder) {
    sg::NurbsSurface s;
    s.kind = sg::NurbsSurfaceKind::Swung;
    s.profile.points = {Vec3(1, 0, 0), Vec3(1, 3, 0)};  // x = radius, y = height
    s.profile.order = 2;
    s.trajectory = full_circle();
    s.ccw = true;
    NurbsRun run;
    NodeReport report = run.report();
    const sg::IndexedFaceSet faces = nurbs_surface_faces(s, false, report);
    ASSERT_FALSE(faces.data.coords.empty());
    for (size_t i = 0; i < faces.data.coords.size(); ++i) {
        const Vec3 p = faces.data.coords[i];
        EXPECT_NEAR(std::hypot(p.x, p.z), 1.0, 1e-15);
        EXPECT_GE(p.y, 0.0);
        EXPECT_LE(p.y, 3.0);
        // The trajectory turns from +x towards +z, the profile goes up: S_u x S_v is outward.
        EXPECT_NEAR(glm::distance(faces.data.normals[i], Vec3(p.x, 0, p.z)), 0.0, 1e-14);
    }
}

TEST(Nurbs, CurveIsDrawnAsOnePolylineOnTheCircle) {
    sg::LineSet l;
    l.kind = sg::LineKind::Curve;
    l.curve = std::make_unique<sg::NurbsCurve>(full_circle(2.0));
    NurbsRun run;
    NodeReport report = run.report();
    const Polylines p = line_geometry(l, report);
    ASSERT_EQ(p.starts.size(), 1u);
    ASSERT_GE(p.positions.size(), 2u * 9 + 1);  // at least X3D's 2n segments
    for (const Vec3& q : p.positions) EXPECT_NEAR(glm::length(q), 2.0, 1e-14);
    EXPECT_EQ(p.positions.front(), p.positions.back());
    // tessellation -3: three segments a control point (X3D 27.4.2).
    l.curve->tessellation = -3;
    EXPECT_EQ(line_geometry(l, report).positions.size(), 27u + 1);
}

TEST(Nurbs, BadKnotsAndOrdersAreWarnedAbout) {
    NurbsRun run;
    {
        NodeReport report = run.report();
        sg::NurbsSurface s = bilinear();
        s.u_knots = {0, 1, 0.5, 1};  // decreasing: the default (clamped uniform) is used
        const sg::IndexedFaceSet faces = nurbs_surface_faces(s, false, report);
        EXPECT_FALSE(faces.coord_index.empty());
        EXPECT_EQ(run.diagnostics.warning_count(), 1u);
    }
    {
        NodeReport report = run.report();
        sg::NurbsSurface s = bilinear();
        s.u_order = 3;  // more than uDimension 2
        EXPECT_TRUE(nurbs_surface_faces(s, false, report).coord_index.empty());
        EXPECT_EQ(run.diagnostics.warning_count(), 2u);
    }
}

}  // namespace
}  // namespace vr
