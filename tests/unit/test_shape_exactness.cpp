// Shapes real files use that the specifications leave to a careful reading: a textured Sphere under
// a rotation (VRML97 6.42), a Box of size 0 in one axis, an Extrusion whose spine is one point.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "geometry/mesh_nodes.h"
#include "render/accel.h"
#include "scene_text.h"

namespace vr {
namespace {

constexpr double kPi = std::numbers::pi;

SurfaceHit hit_of(const FlatScene& flat, const Ray& ray) {
    Accel accel;
    accel.build(flat, 1);
    Hit hit;
    EXPECT_TRUE(accel.intersect(ray, hit));
    return accel.surface(ray, hit, true);
}

TEST(SphereTexture, TurnsWithItsTransform) {
    // VRML97 6.42: s = 0 at -z, increasing counter-clockwise seen from +y, in the Sphere's own
    // coordinates. Seen from +z the unturned sphere shows s = 0.5. Turned by pi/4 about +y, the
    // world direction +z is the object direction (-sin pi/4, 0, cos pi/4): s = 0.5 - 1/8.
    const std::string sphere = R"(
        Shape { appearance Appearance { texture PixelTexture { image 1 1 3 0xFF0000 } }
                geometry Sphere { } })";
    const Ray from_front{Vec3(0, 0, 5), Vec3(0, 0, -1)};
    const testing::FlattenedText plain =
        testing::flatten_scene_text("#VRML V2.0 utf8\n" + sphere, "plain.wrl");
    EXPECT_NEAR(hit_of(plain.flat, from_front).uv.x, 0.5, 1e-12);
    const testing::FlattenedText turned = testing::flatten_scene_text(
        "#VRML V2.0 utf8\nTransform { rotation 0 1 0 0.78539816339744831 children " + sphere + " }",
        "turned.wrl");
    EXPECT_TRUE(turned.flat.meshes.empty());  // still exact, not tessellated
    const SurfaceHit h = hit_of(turned.flat, from_front);
    EXPECT_NEAR(h.uv.x, 0.375, 1e-12);
    EXPECT_NEAR(h.uv.y, 0.5, 1e-12);
    EXPECT_NEAR(h.t, 4.0, 1e-12);
    // Under a uniform scale and a turn, the radius scales and the texture still turns.
    const testing::FlattenedText scaled = testing::flatten_scene_text(
        "#VRML V2.0 utf8\nTransform { scale 2 2 2 rotation 0 1 0 1.5707963267948966 children " +
            sphere + " }",
        "scaled.wrl");
    const SurfaceHit s = hit_of(scaled.flat, from_front);
    EXPECT_NEAR(s.t, 3.0, 1e-12);
    EXPECT_NEAR(s.uv.x, 0.25, 1e-12);  // object direction (-1, 0, 0)
}

TEST(FlatBox, SizeZeroInOneAxisIsATexturedRectangleFromBothSides) {
    const testing::FlattenedText t = testing::flatten_scene_text(R"(#X3D V3.3 utf8
        PROFILE Immersive
        Shape { appearance Appearance { texture PixelTexture { image 2 1 3 0xFF0000 0x00FF00 } }
                geometry Box { size 2 2 0 solid FALSE } })",
                                                                 "card.x3dv");
    EXPECT_EQ(t.build_warnings, 0u) << t.messages;
    // From +z the +z face (s along +x); from -z the -z face (s along -x), so the viewer's left is
    // s near 0 from both sides and the card reads the same way round.
    const SurfaceHit front = hit_of(t.flat, Ray{Vec3(-0.5, 0, 5), Vec3(0, 0, -1)});
    EXPECT_DOUBLE_EQ(front.t, 5.0);
    EXPECT_DOUBLE_EQ(front.uv.x, 0.25);
    EXPECT_EQ(front.ng, Vec3(0, 0, 1));
    const SurfaceHit back = hit_of(t.flat, Ray{Vec3(-0.5, 0, -5), Vec3(0, 0, 1)});
    EXPECT_DOUBLE_EQ(back.t, 5.0);
    EXPECT_DOUBLE_EQ(back.uv.x, 0.75);
    EXPECT_EQ(back.ng, Vec3(0, 0, -1));
    // Zero in two axes is a line: a warning, nothing drawn.
    const testing::FlattenedText line = testing::flatten_scene_text(
        "#VRML V2.0 utf8\nShape { geometry Box { size 2 0 0 } }", "line.wrl");
    EXPECT_EQ(line.build_warnings, 1u);
    EXPECT_TRUE(line.flat.quadrics.empty());
}

TEST(PointSpineExtrusion, OrientationAloneTurnsTheCrossSection) {
    // Three coincident spine points; the cross-section (0,0)-(1,0) turned about +y by 0, pi/2,
    // pi: a half disc in the y = 0 plane. Rotation about +y by a takes (1,0,0) to (cos a, 0,
    // -sin a).
    sg::Extrusion e;
    e.cross_section = {Vec2(0, 0), Vec2(1, 0)};
    e.spine = {Vec3(0), Vec3(0), Vec3(0)};
    e.scale = {Vec2(1)};
    e.orientation = {Vec4(0, 1, 0, 0), Vec4(0, 1, 0, kPi / 2), Vec4(0, 1, 0, kPi)};
    e.ccw = true;
    e.solid = false;
    Diagnostics diagnostics;
    const sg::Origin origin;
    NodeReport report(diagnostics, origin);
    const sg::IndexedFaceSet f = extrusion_faces(e, false, report);
    EXPECT_EQ(diagnostics.warning_count(), 0u);
    ASSERT_EQ(f.data.coords.size(), 6u);
    for (int i = 0; i < 3; ++i) {
        const double a = kPi / 2 * i;
        EXPECT_NEAR(glm::length(f.data.coords[2 * i + 1] - Vec3(std::cos(a), 0, -std::sin(a))), 0.0,
                    1e-15);
        EXPECT_EQ(f.data.coords[2 * i], Vec3(0));
    }
    EXPECT_FALSE(f.coord_index.empty());  // the two sides (triangles, one corner at the point)
    // Nothing changing along a point spine: nothing to draw, one warning.
    e.orientation = {Vec4(0, 1, 0, 0)};
    Diagnostics d2;
    NodeReport r2(d2, origin);
    EXPECT_TRUE(extrusion_faces(e, false, r2).coord_index.empty());
    EXPECT_EQ(d2.warning_count(), 1u);
}

TEST(ZeroScale, MeshesAreDrawnFlatAndExactShapesSkippedWithAWarning) {
    // Xj3D's CombineTransform/shapeuse4.x3dv: a Transform with scale 1 1.5 0 over a triangle at
    // z = -1. Browsers draw the triangle pressed into the z = 0 plane; so does vrmlray, with one
    // warning that says the exact shapes (the sphere here) are skipped. The two corners go to
    // (x + 2, 1.5 * 1.5, 0) and the apex (0, 1, -1) to (2, 1.5 * (1 + 1.5), 0).
    const testing::FlattenedText flat = testing::flatten_scene_text(
        "#X3D V3.3 utf8\nPROFILE Immersive\n"
        "Transform { scale 1 1.5 0 children Transform { translation 2 1.5 0 children [\n"
        "  Shape { geometry IndexedFaceSet { coord Coordinate { point [1 0 -1, -1 0 -1, 0 1 -1] }\n"
        "                                    coordIndex [0 2 1] } }\n"
        "  Shape { geometry Sphere {} } ] } }",
        "shapeuse4.x3dv");
    EXPECT_EQ(flat.build_warnings, 1u) << flat.messages;
    EXPECT_TRUE(flat.flat.spheres.empty());  // a sphere pressed flat is no sphere: skipped
    EXPECT_TRUE(flat.flat.quadrics.empty());
    size_t triangles = 0;
    for (const Mesh& m : flat.flat.meshes) {
        triangles += m.triangle_count();
        EXPECT_TRUE(m.normals.empty());  // the flat face's own normal
        for (const Vec3& p : m.positions) EXPECT_EQ(p.z, 0.0);
        if (m.positions.size() == 3) {  // in the face's corner order, coordIndex 0 2 1
            EXPECT_EQ(m.positions[0], Vec3(3, 2.25, 0));
            EXPECT_EQ(m.positions[1], Vec3(2, 3.75, 0));
            EXPECT_EQ(m.positions[2], Vec3(1, 2.25, 0));
        }
    }
    EXPECT_EQ(triangles, 1u);
}

}  // namespace
}  // namespace vr
