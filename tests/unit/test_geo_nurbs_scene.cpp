// The Geospatial and NURBS nodes through the reader and the scene build (src/scene/build_geo.cpp,
// build_nurbs.cpp) and, for GeoPositionInterpolator, the animator: what a file's nodes become.
#include <gtest/gtest.h>

#include <cmath>

#include "anim/animator.h"
#include "core/geo.h"
#include "geometry/lines.h"
#include "geometry/mesh_nodes.h"
#include "geometry/nurbs.h"
#include "geometry/polygon_mesh.h"
#include "parser/load.h"
#include "scene/build.h"
#include "scene/transform.h"

namespace vr {
namespace {

struct Built {
    LoadedScene loaded;
    Diagnostics diagnostics;
    Scene scene;
    std::string messages() const { return diagnostics.format(loaded.sources); }
};

std::unique_ptr<Built> build(const std::string& body) {
    auto b = std::make_unique<Built>();
    b->loaded = load_scene_text("#X3D V3.3 utf8\nPROFILE Full\n" + body, "test.x3dv");
    EXPECT_TRUE(b->loaded.ok()) << b->loaded.diagnostics.format(b->loaded.sources);
    b->scene = build_scene(b->loaded, b->diagnostics);
    return b;
}

const geo::System kGd = [] {
    std::vector<std::string> problems;
    return geo::parse_system(std::vector<std::string>{"GD"}, problems);
}();

// LA's point from gd_points.txt; rotateYUp there makes its local frame the world's axes.
constexpr const char* kOrigin =
    "DEF O GeoOrigin { geoCoords 34.07636 -118.26667 0 rotateYUp TRUE }";

TEST(GeoScene, GeoLocationPlacesItsChildrenInTheLocalFrame) {
    const auto b = build(std::string("GeoLocation { geoOrigin ") + kOrigin +
                         " geoCoords 34.07636 -118.26667 100 children Shape { geometry Box {} } }");
    ASSERT_EQ(b->scene.matrices.size(), 1u) << b->messages();
    const Mat4& m = b->scene.matrices[0];
    // 100 m up from the origin, axes unturned (the origin's frame is the location's up to the
    // 100 m of height, which does not turn it): 1e-8 m and 1e-12 are rounding of 6.4e6 m values.
    EXPECT_NEAR(m[3].x, 0.0, 1e-8);
    EXPECT_NEAR(m[3].y, 100.0, 1e-8);
    EXPECT_NEAR(m[3].z, 0.0, 1e-8);
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) EXPECT_NEAR(m[c][r], c == r ? 1.0 : 0.0, 1e-12);
    EXPECT_EQ(b->diagnostics.warning_count(), 0u) << b->messages();
}

TEST(GeoScene, GeoTransformActsInTheTangentFrameAtItsCenter) {
    // At the origin's own point with rotateYUp, the tangent frame is the world's axes: the
    // GeoTransform is its plain Transform (translation, then a quarter turn about +Y).
    const auto b = build(std::string("GeoTransform { geoOrigin ") + kOrigin +
                         " geoCenter 34.07636 -118.26667 0 translation 1 2 3"
                         " rotation 0 1 0 1.5707963267948966 children Shape { geometry Box {} } }");
    ASSERT_EQ(b->scene.matrices.size(), 1u) << b->messages();
    const Mat4& m = b->scene.matrices[0];
    // 1e-8: the frame's products round at 1e-16 of 6.4e6 m.
    EXPECT_NEAR(glm::distance(transform_point(m, Vec3(0)), Vec3(1, 2, 3)), 0.0, 1e-8);
    EXPECT_NEAR(glm::distance(transform_point(m, Vec3(1, 0, 0)), Vec3(1, 2, 2)), 0.0, 1e-8);
}

TEST(GeoScene, GeoLodDrawsItsRootNodeWhenNoChildFileLoads) {
    const auto b =
        build("GeoLOD { rootNode Shape { geometry Box {} } child1Url \"missing.x3dv\" }");
    EXPECT_EQ(b->scene.shapes.size(), 1u) << b->messages();
}

TEST(GeoScene, GeoCoordinatePointsAreGeocentricLessTheOrigin) {
    // Without rotateYUp the world point is the CartConvert value (tests/data/geo) less the
    // origin's: New York's minus LA's, both from gd_wgs84_cartconvert.txt.
    const auto b = build(
        "Shape { geometry IndexedLineSet { coordIndex [0 1] coord GeoCoordinate {"
        " geoOrigin GeoOrigin { geoCoords 34.07636 -118.26667 0 }"
        " point [34.07636 -118.26667 0, 40.74705 -74.02514 200000] } } }");
    ASSERT_EQ(b->scene.geometries.size(), 1u);
    const auto& lines = *std::get<std::unique_ptr<sg::LineSet>>(b->scene.geometries[0].shape);
    ASSERT_EQ(lines.coords.size(), 2u);
    EXPECT_NEAR(glm::length(lines.coords[0]), 0.0, 1e-9);
    const Vec3 want = Vec3(1373461.248140714, -4797772.755003097, 4271726.593745414) -
                      Vec3(-2504514.520968652, -4657877.377830366, 3553465.425105664);
    EXPECT_NEAR(glm::distance(lines.coords[1], want), 0.0, 6e-3);  // 1e-9 of the Earth's radius
}

TEST(GeoScene, GeoElevationGridFacesUpAndFollowsTheEllipsoid) {
    // 3 x 2 posts 0.01 degree apart east (x) and north (z) from the origin, heights 0..5 m.
    const auto b = build(std::string("Shape { geometry GeoElevationGrid { geoOrigin ") + kOrigin +
                         " geoGridOrigin 34.07636 -118.26667 0 xDimension 3 zDimension 2"
                         " xSpacing 0.01 zSpacing 0.01 height [0 1 2 3 4 5] yScale 2 } }");
    ASSERT_EQ(b->scene.geometries.size(), 1u) << b->messages();
    const auto& f = *std::get<std::unique_ptr<sg::IndexedFaceSet>>(b->scene.geometries[0].shape);
    ASSERT_EQ(f.data.coords.size(), 6u);
    const geo::Origin origin = geo::make_origin(kGd, Vec3(34.07636, -118.26667, 0), true);
    // Post (i, j) at latitude +0.01 j, longitude +0.01 i, height 2 * height[i + 3 j].
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 3; ++i) {
            const Vec3 want = origin.world_point(geo::to_geocentric(
                kGd, Vec3(34.07636 + 0.01 * j, -118.26667 + 0.01 * i, 2.0 * (i + 3 * j))));
            EXPECT_NEAR(glm::distance(f.data.coords[size_t(i + 3 * j)], want), 0.0, 1e-8);
        }
    EXPECT_GT(f.data.coords[1].x, 900.0);    // east is +X (0.01 degree of longitude ~ 921 m)
    EXPECT_LT(f.data.coords[3].z, -1100.0);  // north is -Z (0.01 degree of latitude ~ 1109 m)
    // Each face's corners turn counter-clockwise seen from above (+Y): the front faces up.
    Diagnostics d;
    sg::Origin o;
    NodeReport report(d, o);
    const TriMesh mesh = triangulate_face_set(f, false, report);
    ASSERT_EQ(mesh.triangle_count(), 4u);
    for (size_t t = 0; t < mesh.triangles.size(); t += 3) {
        const Vec3 a = mesh.positions[mesh.triangles[t]], c = mesh.positions[mesh.triangles[t + 1]],
                   e = mesh.positions[mesh.triangles[t + 2]];
        EXPECT_GT(glm::cross(c - a, e - a).y, 0.0);
    }
    EXPECT_EQ(f.data.texcoords.size(), 6u);  // the ElevationGrid default: s = i/2, t = j
    EXPECT_EQ(f.data.texcoords[5], Vec2(1.0, 1.0));
}

TEST(GeoScene, GeoViewpointLooksDownWithTheUsualRotation) {
    // X3D 25.4.10: the orientation is relative to the local frame; 1 0 0 -pi/2 looks straight down.
    const auto b =
        build(std::string("GeoViewpoint { geoOrigin ") + kOrigin +
              " position 34.07636 -118.26667 5000 orientation 1 0 0 -1.5707963267948966 }");
    ASSERT_EQ(b->scene.viewpoints.size(), 1u);
    const sg::Viewpoint& v = b->scene.viewpoints[0];
    EXPECT_NEAR(glm::distance(v.position, Vec3(0, 5000, 0)), 0.0, 1e-7);
    const Vec3 look = rotation_matrix(v.orientation) * Vec3(0, 0, -1);
    EXPECT_NEAR(glm::distance(look, Vec3(0, -1, 0)), 0.0, 1e-12);
    const Vec3 up = rotation_matrix(v.orientation) * Vec3(0, 1, 0);
    EXPECT_NEAR(glm::distance(up, Vec3(0, 0, -1)), 0.0, 1e-12);  // the top of the view is north
}

TEST(GeoScene, GeoPositionInterpolatorMovesAGeoLocation) {
    auto b = std::make_unique<Built>();
    b->loaded = load_scene_text(R"(#X3D V3.3 utf8
PROFILE Full
DEF Clock TimeSensor { loop TRUE cycleInterval 4 }
DEF Path GeoPositionInterpolator { key [0 1] keyValue [10 20 0, 30 60 1000] }
DEF Here GeoLocation { children Shape { geometry Sphere {} } }
DEF Moved Transform {}
ROUTE Clock.fraction_changed TO Path.set_fraction
ROUTE Path.geovalue_changed TO Here.set_geoCoords
ROUTE Path.value_changed TO Moved.set_translation
)",
                                "anim.x3dv");
    ASSERT_TRUE(b->loaded.ok()) << b->loaded.diagnostics.format(b->loaded.sources);
    Animator animator(b->loaded.tree, b->diagnostics);
    EXPECT_TRUE(animator.evaluate(1.0));  // fraction 1/4: geo (15, 30, 250), blended in GD
    NodeTree& tree = b->loaded.tree;
    NodeId here = 0, moved = 0;
    for (NodeId i = 0; i < tree.nodes.size(); ++i) {
        if (tree.def_name(i) == "Here") here = i;
        if (tree.def_name(i) == "Moved") moved = i;
    }
    const FieldView coords = tree.get(here, "geoCoords");
    ASSERT_EQ(coords.numbers.size(), 3u);
    EXPECT_EQ(Vec3(coords.numbers[0], coords.numbers[1], coords.numbers[2]), Vec3(15, 30, 250));
    // value_changed: the same point in world (here geocentric) coordinates, single precision
    // (SFVec3f) as the field holds it: 1 m of 6.4e6.
    const FieldView t = tree.get(moved, "translation");
    const Vec3 want = geo::to_geocentric(kGd, Vec3(15, 30, 250));
    EXPECT_NEAR(glm::distance(Vec3(t.numbers[0], t.numbers[1], t.numbers[2]), want), 0.0, 1.0);
    // And the scene built from the animated tree puts the sphere there.
    b->scene = build_scene(b->loaded, b->diagnostics);
    ASSERT_EQ(b->scene.matrices.size(), 1u) << b->messages();  // Moved only translates
    EXPECT_NEAR(glm::distance(Vec3(b->scene.matrices[0][3]), want), 0.0, 1e-6);
}

TEST(NurbsScene, PatchTrimmedCurveAndSetFromAFile) {
    const auto b = build(R"(
DEF Patch Shape { geometry NurbsPatchSurface {
  uDimension 2 vDimension 2 uOrder 2 vOrder 2 uTessellation 4 vTessellation 4
  controlPoint CoordinateDouble { point [0 0 0, 1 0 0, 0 1 0, 1 1 0] } } }
Shape { geometry NurbsTrimmedSurface {
  uDimension 2 vDimension 2 uOrder 2 vOrder 2
  controlPoint Coordinate { point [0 0 0, 1 0 0, 0 1 0, 1 1 0] }
  trimmingContour Contour2D { children [
    ContourPolyline2D { controlPoint [0.25 0.25, 0.25 0.75, 0.75 0.75] }
    NurbsCurve2D { order 2 controlPoint [0.75 0.75, 0.75 0.25, 0.25 0.25] } ] } } }
Shape { geometry NurbsCurve { order 2 controlPoint Coordinate { point [0 0 0, 1 0 0, 1 1 0] } } }
NurbsSet { geometry USE Patch }
)");
    EXPECT_EQ(b->scene.shapes.size(), 3u) << b->messages();  // NurbsSet draws nothing itself
    ASSERT_EQ(b->scene.geometries.size(), 3u);
    Diagnostics d;
    sg::Origin o;
    NodeReport report(d, o);
    const auto& patch = *std::get<std::unique_ptr<sg::NurbsSurface>>(b->scene.geometries[0].shape);
    EXPECT_EQ(patch.points.size(), 4u);
    EXPECT_NEAR(
        triangulate_face_set(nurbs_surface_faces(patch, false, report), false, report).area(), 1.0,
        1e-12);
    const auto& trimmed =
        *std::get<std::unique_ptr<sg::NurbsSurface>>(b->scene.geometries[1].shape);
    ASSERT_EQ(trimmed.trimming.size(), 1u);
    EXPECT_EQ(trimmed.trimming[0].size(), 2u);  // the two pieces of the one contour, in order
    EXPECT_NEAR(
        triangulate_face_set(nurbs_surface_faces(trimmed, false, report), false, report).area(),
        0.75, 1e-12);
    const auto& curve = *std::get<std::unique_ptr<sg::LineSet>>(b->scene.geometries[2].shape);
    const Polylines p = line_geometry(curve, report);
    ASSERT_EQ(p.starts.size(), 1u);
    EXPECT_EQ(p.positions.front(), Vec3(0, 0, 0));
    EXPECT_EQ(p.positions.back(), Vec3(1, 1, 0));
    EXPECT_EQ(d.warning_count(), 0u);
}

}  // namespace
}  // namespace vr
