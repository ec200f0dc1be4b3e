// X3D `solid TRUE`: back faces are not drawn for camera and secondary rays (docs/rendering.md, Back
// faces); VRML97 files, see-through surfaces and shadow rays keep both faces.
#include <gtest/gtest.h>

#include "render/accel.h"
#include "scene_text.h"

namespace vr {
namespace {

const std::string kX3d = "#X3D V3.3 utf8\nPROFILE Immersive\n";
const std::string kVrml = "#VRML V2.0 utf8\n";

// The centre pixel of a 16x16 render from the scene's own Viewpoint.
std::array<float, 4> centre(const std::string& text, const std::string& path) {
    const testing::FlattenedText t = testing::flatten_scene_text(text, path);
    EXPECT_EQ(t.build_warnings, 0u) << t.messages;
    RenderOptions o;
    o.width = o.height = 16;
    const Image im = testing::render_from_its_camera(t.flat, o);
    const float* p = im.pixel(8, 8);
    return {p[0], p[1], p[2], p[3]};
}

// A camera at the centre of a box 4 units wide, looking along -z, headlight on.
std::string inside_box(const std::string& header, const std::string& box_fields,
                       const std::string& material = "material Material { }") {
    return header + "Viewpoint { position 0 0 0 }\nShape { appearance Appearance { " + material +
           " } geometry Box { size 4 4 4 " + box_fields + " } }";
}

TEST(BackFaces, SolidBoxSeenFromInsideIsCulledInX3d) {
    // X3D: the inside of the box is its back faces: nothing is drawn, the background (alpha 0)
    // shows.
    EXPECT_EQ(centre(inside_box(kX3d, ""), "box.x3dv")[3], 0.0f);
    // solid FALSE draws them; VRML97 (no solid field on Box) always does.
    EXPECT_EQ(centre(inside_box(kX3d, "solid FALSE"), "box.x3dv")[3], 1.0f);
    EXPECT_EQ(centre(inside_box(kVrml, ""), "box.wrl")[3], 1.0f);
    // A see-through box keeps both faces: its far inside wall is seen (alpha 1 - 0.5).
    const auto glass =
        centre(inside_box(kX3d, "", "material Material { transparency 0.5 }"), "box.x3dv");
    EXPECT_NEAR(glass[3], 0.5f, 1e-6);
}

TEST(BackFaces, SphereSeenFromInsideIsCulledInX3d) {
    // A sky sphere around the camera needs `solid FALSE` in X3D (as in the browsers); from
    // outside, a solid sphere is drawn (its front is always met first).
    const std::string inside =
        "Viewpoint { position 0 0 0 }\n"
        "Shape { appearance Appearance { material Material { } } "
        "geometry Sphere { radius 5 SOLID } }";
    auto with = [&](const std::string& solid) {
        std::string s = inside;
        return s.replace(s.find("SOLID"), 5, solid);
    };
    EXPECT_EQ(centre(kX3d + with(""), "sky.x3dv")[3], 0.0f);
    EXPECT_EQ(centre(kX3d + with("solid FALSE"), "sky.x3dv")[3], 1.0f);
    EXPECT_EQ(centre(kVrml + with(""), "sky.wrl")[3], 1.0f);
    std::string outside = with("");
    outside.replace(outside.find("position 0 0 0"), 14, "position 0 0 20");
    EXPECT_EQ(centre(kX3d + outside, "ball.x3dv")[3], 1.0f);
}

TEST(BackFaces, ConeWithoutBottomShowsTheBackgroundInside) {
    // The NIST Cone/no_bottom case: looking up into a cone through its missing bottom. X3D: the
    // inside of the side is culled and the background shows; VRML97: the inside is drawn.
    const std::string scene = R"(
        Viewpoint { position 0 -5 0 orientation 1 0 0 1.5707963267948966 }
        Shape { appearance Appearance { material Material { } } geometry Cone { bottom FALSE } })";
    EXPECT_EQ(centre(kX3d + scene, "cone.x3dv")[3], 0.0f);
    EXPECT_EQ(centre(kVrml + scene, "cone.wrl")[3], 1.0f);
}

TEST(BackFaces, MeshesFollowTheirFrontFaceAndShadowsAreNotCulled) {
    // A square facing +z (counter-clockwise seen from +z). Seen from -z it is culled in X3D; a ray
    // from the far side to a light on the near side is still blocked (shadows keep both faces).
    const std::string quad = R"(
        Shape { appearance Appearance { material Material { } }
          geometry IndexedFaceSet { coord Coordinate { point [-1 -1 0, 1 -1 0, 1 1 0, -1 1 0] }
                                    coordIndex [0 1 2 3] } })";
    const testing::FlattenedText t = testing::flatten_scene_text(kX3d + quad, "quad.x3dv");
    Accel accel;
    accel.build(t.flat, 1);
    Hit hit;
    EXPECT_TRUE(accel.intersect(Ray{Vec3(0, 0, 5), Vec3(0, 0, -1)}, hit));
    EXPECT_DOUBLE_EQ(hit.t, 5.0);
    EXPECT_FALSE(accel.intersect(Ray{Vec3(0, 0, -5), Vec3(0, 0, 1)}, hit));
    EXPECT_TRUE(accel.intersect_any_face(Ray{Vec3(0, 0, -5), Vec3(0, 0, 1)}, hit));
    EXPECT_EQ(accel.transmittance(Ray{Vec3(0, 0, -5), Vec3(0, 0, 1), 10.0}), 0.0);
    // `ccw FALSE` makes -z the front: now the ray from -z hits.
    std::string cw = quad;
    cw.replace(cw.find("coordIndex"), 0, "ccw FALSE ");
    const testing::FlattenedText f = testing::flatten_scene_text(kX3d + cw, "quad.x3dv");
    Accel flipped;
    flipped.build(f.flat, 1);
    EXPECT_TRUE(flipped.intersect(Ray{Vec3(0, 0, -5), Vec3(0, 0, 1)}, hit));
    EXPECT_FALSE(flipped.intersect(Ray{Vec3(0, 0, 5), Vec3(0, 0, -1)}, hit));
}

TEST(BackFaces, ACulledFaceLetsTheRayFindWhatIsBehindIt) {
    // Two X3D squares facing +z at z = 0 and z = -2; from z = -5 looking +z the first is seen
    // from behind (culled) and so is the second: no hit. From inside the pair (z = -1) looking -z
    // the second is a front face at distance 1.
    const std::string squares = R"(
        Transform { translation 0 0 DZ children Shape { appearance Appearance { material Material { } }
          geometry IndexedFaceSet { coord Coordinate { point [-1 -1 0, 1 -1 0, 1 1 0, -1 1 0] }
                                    coordIndex [0 1 2 3] } } })";
    std::string text = kX3d;
    for (const char* dz : {"0", "-2"}) {
        std::string s = squares;
        s.replace(s.find("DZ"), 2, dz);
        text += s;
    }
    const testing::FlattenedText t = testing::flatten_scene_text(text, "two.x3dv");
    Accel accel;
    accel.build(t.flat, 1);
    Hit hit;
    EXPECT_FALSE(accel.intersect(Ray{Vec3(0.5, 0.25, -5), Vec3(0, 0, 1)}, hit));
    ASSERT_TRUE(accel.intersect(Ray{Vec3(0.5, 0.25, -1), Vec3(0, 0, -1)}, hit));
    EXPECT_DOUBLE_EQ(hit.t, 1.0);
    // A box behind a culled face: the ray from z = -1 passes the square at z = 0 from behind and
    // meets the front of a box spanning z in [2, 4]; t counts from the ray's own origin: 3.
    const testing::FlattenedText b =
        testing::flatten_scene_text(text + R"( Transform { translation 0 0 3 children Shape {
            appearance Appearance { material Material { } } geometry Box { size 1 1 2 } } })",
                                    "behind.x3dv");
    Accel with_box;
    with_box.build(b.flat, 1);
    ASSERT_TRUE(with_box.intersect(Ray{Vec3(0.25, 0.25, -1), Vec3(0, 0, 1)}, hit));
    EXPECT_NEAR(hit.t, 3.0, 1e-12);
}

}  // namespace
}  // namespace vr
