// The VRML97 lighting equation (4.14.4) from file to pixel: coloured lights, `on FALSE`,
// attenuation, the radius (beyond it a light adds nothing, not even its ambient term) and its
// scaling by the transform. Every expected value is the closed form at the centre pixel, where the
// camera ray meets the plane z = 0 at the origin with N = V = +z.
#include <gtest/gtest.h>

#include <string>

#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/render.h"
#include "scene/build.h"

namespace vr {
namespace {

// A few double operations on exact inputs, then the float pixel: its rounding (6e-8 relative) on
// values below 1 is the limit.
constexpr double kPixelTolerance = 1e-6;

const Vec3 kDiffuse(0.8, 0.6, 0.4);
constexpr double kMaterialAmbient = 0.5;

// The plane under `lights`, without headlight; returns the centre pixel's RGB.
Vec3 centre_pixel(const std::string& lights) {
    const std::string text =
        "#VRML V2.0 utf8\nNavigationInfo { headlight FALSE }\nViewpoint { position 0 0 10 "
        "fieldOfView 0.3 }\n"
        "Shape { appearance Appearance { material Material { diffuseColor 0.8 0.6 0.4 "
        "ambientIntensity 0.5 "
        "specularColor 0 0 0 } } geometry IndexedFaceSet { coord Coordinate { point [-50 -50 0, 50 "
        "-50 0, "
        "50 50 0, -50 50 0] } coordIndex [0 1 2 3 -1] } }\n" +
        lights;
    LoadedScene loaded = load_scene_text(text, "lighting.wrl");
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenStats stats;
    const FlatScene flat = flatten_scene(scene, FlattenOptions{}, diagnostics, stats);
    EXPECT_FALSE(diagnostics.has_errors());
    RenderOptions o;
    o.width = o.height = 11;  // odd: the centre pixel's ray is the view axis
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(flat, o, camera, error)) << error;
    RenderStats rs;
    const Image img = render_image(flat, camera, o, nullptr, rs);
    const float* p = img.pixel(5, 5);
    EXPECT_EQ(p[3], 1.0f);  // the plane covers the pixel
    return Vec3(p[0], p[1], p[2]);
}

void expect_rgb(const Vec3& got, const Vec3& want) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], kPixelTolerance) << "channel " << c;
}

// on * att * spot * I_Lrgb * (Ia * Ia_material * Od + I * Od * N.L), N.L = 1, no specular.
Vec3 lit(const Vec3& color, double intensity, double ambient, double att) {
    return att * color * kDiffuse * (ambient * kMaterialAmbient + intensity);
}

TEST(RenderLighting, ColouredDirectionalLight) {
    const Vec3 got = centre_pixel(
        "DirectionalLight { direction 0 0 -1 color 1 0.5 0.25 intensity 0.7 "
        "ambientIntensity 0.2 }\n");
    expect_rgb(got, lit(Vec3(1.0, 0.5, 0.25), 0.7, 0.2, 1.0));
}

TEST(RenderLighting, PointLightAttenuationAndColour) {
    // d = 2: 1 / max(a0 + a1 d + a2 d^2, 1) = 1 / (1 + 1 + 1).
    const Vec3 got = centre_pixel(
        "PointLight { location 0 0 2 color 0.25 1 0.5 intensity 0.8 "
        "ambientIntensity 0.3 attenuation 1 0.5 0.25 radius 10 }\n");
    expect_rgb(got, lit(Vec3(0.25, 1.0, 0.5), 0.8, 0.3, 1.0 / 3.0));
}

TEST(RenderLighting, AttenuationBelowOneIsClampedToOne) {
    // a0 = 0.1: 1 / max(0.1, 1) = 1, not 10.
    const Vec3 got =
        centre_pixel("PointLight { location 0 0 2 intensity 0.5 attenuation 0.1 0 0 }\n");
    expect_rgb(got, lit(Vec3(1.0), 0.5, 0.0, 1.0));
}

TEST(RenderLighting, LightsThatAreOffAddNothing) {
    const Vec3 got = centre_pixel(
        "DirectionalLight { direction 0 0 -1 intensity 0.6 }\n"
        "DirectionalLight { on FALSE direction 0 0 -1 color 1 0 0 intensity 1 ambientIntensity 1 "
        "}\n"
        "PointLight { on FALSE location 0 0 1 ambientIntensity 1 }\n"
        "SpotLight { on FALSE location 0 0 1 direction 0 0 -1 ambientIntensity 1 }\n");
    expect_rgb(got, lit(Vec3(1.0), 0.6, 0.0, 1.0));
}

TEST(RenderLighting, NothingBeyondTheRadiusNotEvenAmbient) {
    // The point is 5 from each light, beyond radius 4.99: the ambient term goes with the rest.
    const Vec3 got = centre_pixel(
        "PointLight { location 0 0 5 radius 4.99 ambientIntensity 1 }\n"
        "SpotLight { location 0 0 5 direction 0 0 -1 radius 4.99 ambientIntensity 1 }\n"
        "DirectionalLight { direction 0 0 -1 intensity 0.25 }\n");
    expect_rgb(got, lit(Vec3(1.0), 0.25, 0.0, 1.0));
    // Just inside (radius 5.01), both add their full terms.
    const Vec3 inside = centre_pixel(
        "PointLight { location 0 0 5 radius 5.01 ambientIntensity 1 }\n"
        "SpotLight { location 0 0 5 direction 0 0 -1 radius 5.01 ambientIntensity 1 }\n");
    expect_rgb(inside, 2.0 * lit(Vec3(1.0), 1.0, 1.0, 1.0));
}

TEST(RenderLighting, RadiusScalesWithTheTransform) {
    // Scale 2: the light sits at (0, 0, 4) with radius 2 * 2.5 = 5 > 4, so it lights the point;
    // unscaled, radius 2.5 at distance 4 would not. Attenuation 1 0 0 is 1 in any units.
    const Vec3 got = centre_pixel(
        "Transform { scale 2 2 2 children PointLight { location 0 0 2 radius 2.5 "
        "color 0 1 0 intensity 0.5 } }\n");
    expect_rgb(got, lit(Vec3(0.0, 1.0, 0.0), 0.5, 0.0, 1.0));
    const Vec3 unscaled =
        centre_pixel("PointLight { location 0 0 4 radius 2.5 color 0 1 0 intensity 0.5 }\n");
    expect_rgb(unscaled, Vec3(0.0));
}

}  // namespace
}  // namespace vr
