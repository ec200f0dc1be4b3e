// The typed scene holds only checked Viewpoint and Background values: the scene build replaces
// what cannot be a camera or a sky (with one warning naming the node), so that flattening copies
// them as they are.
#include <gtest/gtest.h>

#include "core/math.h"
#include "parser/load.h"
#include "scene/build.h"

namespace vr {
namespace {

struct Built {
    LoadedScene loaded;
    Diagnostics diagnostics;
    Scene scene;
};

Built build(const std::string& body) {
    Built b;
    b.loaded = load_scene_text("#VRML V2.0 utf8\n" + body, "test.wrl");
    EXPECT_TRUE(b.loaded.ok()) << b.loaded.diagnostics.format(b.loaded.sources);
    b.scene = build_scene(b.loaded, b.diagnostics);
    return b;
}

std::string messages(const Built& b) {
    std::string out;
    for (const Diagnostic& d : b.diagnostics.all()) out += d.message + "\n";
    return out;
}

TEST(SceneBindables, FieldOfViewOutsideZeroPiIsReplacedInTheScene) {
    // Exact comparisons: the replacements are the constants docs/manual.md, Camera names, not
    // computed. 3.141592653589793 reads as the double nearest pi, kPi itself: pi is not a camera.
    for (auto [fov, expected] :
         {std::pair{"0", 0.785398}, std::pair{"-1", 0.785398}, std::pair{"4", kPi - 0.01},
          std::pair{"3.141592653589793", kPi - 0.01}}) {
        const Built b = build(std::string("Viewpoint { fieldOfView ") + fov + " }");
        ASSERT_EQ(b.scene.viewpoints.size(), 1u);
        EXPECT_EQ(b.scene.viewpoints[0].field_of_view, expected) << fov;
        EXPECT_NE(messages(b).find("lies outside (0, pi)"), std::string::npos) << fov;
    }
    const Built narrow = build("Viewpoint { fieldOfView 3.2e-8 }");
    EXPECT_EQ(narrow.scene.viewpoints[0].field_of_view, 3.2e-8);  // every value in (0, pi) is kept
    EXPECT_EQ(messages(narrow), "");
}

TEST(SceneBindables, BackgroundAnglesAndColoursAreMadeToMatch) {
    const Built b = build(
        "Background { skyColor [0 0 1, 0 1 0, 1 0 0] skyAngle [1] "
        "groundColor [0.5 0.5 0.5] groundAngle [0.5 1] }");
    ASSERT_EQ(b.scene.backgrounds.size(), 1u);
    const sg::Background& bg = b.scene.backgrounds[0];
    EXPECT_EQ(bg.sky_angle.size(), 1u);
    EXPECT_EQ(bg.sky_color.size(), 2u);  // one more colour than angles; the third is dropped
    EXPECT_EQ(bg.sky_color[1], Vec3(0, 1, 0));
    EXPECT_EQ(bg.ground_angle.size(), 0u);  // a single ground colour takes no angle
    EXPECT_EQ(bg.ground_color.size(), 1u);
    // One warning per node and cause (as every node report): the sky's stands for both.
    EXPECT_EQ(messages(b),
              "Background: skyColor needs one value more than skyAngle; the extra values are "
              "ignored\n");

    const Built ground = build("Background { groundColor [0 0 0, 1 1 1] groundAngle [0.5 1 1.5] }");
    EXPECT_EQ(ground.scene.backgrounds[0].ground_angle, std::vector<double>{0.5});
    EXPECT_NE(messages(ground).find("groundColor needs one value more than groundAngle"),
              std::string::npos)
        << messages(ground);

    const Built empty = build("Background { skyAngle [1 2] }");
    ASSERT_EQ(empty.scene.backgrounds.size(), 1u);
    // No skyColor: the VRML97 default, one black colour, and so no angle.
    EXPECT_EQ(empty.scene.backgrounds[0].sky_color, std::vector<Vec3>{Vec3(0.0)});
    EXPECT_TRUE(empty.scene.backgrounds[0].sky_angle.empty());

    const Built good = build("Background { skyColor [0 0 1, 1 1 1] skyAngle [1.5] }");
    EXPECT_EQ(good.scene.backgrounds[0].sky_color.size(), 2u);
    EXPECT_EQ(messages(good), "");
}

}  // namespace
}  // namespace vr
