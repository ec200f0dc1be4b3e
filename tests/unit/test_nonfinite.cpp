// A NaN in the tracer is a bug: it must be counted where it arises (light term, gas, shading) and
// replaced by 0, so that no image holds NaN and no NaN goes unreported.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>

#include "render/render.h"
#include "test_render_util.h"

namespace vr {
namespace {

using testing::add_light;
using testing::add_shading;
using testing::add_sphere;
using testing::empty_scene;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kSize = 9;  // 81 pixels; the unit sphere fills the middle ones

struct Result {
    Image image;
    RenderStats stats;
};

Result render(const FlatScene& scene, const std::optional<Vec3>& background = std::nullopt) {
    RenderOptions o;
    o.background = background;
    o.width = o.height = kSize;
    o.threads = 2;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(scene, o, camera, error)) << error;
    Result r;
    r.image = render_image(scene, camera, o, nullptr, r.stats);
    return r;
}

void expect_all_finite(const Image& img) {
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            for (int c = 0; c < 4; ++c)
                ASSERT_TRUE(std::isfinite(img.pixel(x, y)[c])) << x << "," << y;
}

FlatScene lit_sphere(const Material& m, const Light& light) {
    FlatScene scene = empty_scene();
    add_sphere(scene, Vec3(0.0), 1.0, add_shading(scene, m));
    add_light(scene, light);
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 5.0), 0.6));
    return scene;
}

Light white_directional() {
    Light l;
    l.direction = Vec3(0.0, 0.0, -1.0);
    return l;
}

TEST(NonFinite, CleanSceneCountsNothing) {
    Result r = render(lit_sphere(Material{}, white_directional()));
    EXPECT_EQ(r.stats.nonfinite.total(), 0u);
    EXPECT_GT(r.image.pixel(kSize / 2, kSize / 2)[0], 0.1f);  // the sphere is there and lit
}

TEST(NonFinite, NaNLightColourIsCountedAsLightTerms) {
    Light l = white_directional();
    l.color = Vec3(kNaN, 1.0, 1.0);
    Result r = render(lit_sphere(Material{}, l));
    // One NaN term per sphere pixel (the light reaches every visible point), none elsewhere.
    EXPECT_GT(r.stats.nonfinite.light, 0u);
    EXPECT_LE(r.stats.nonfinite.light, uint64_t(kSize * kSize));
    EXPECT_EQ(r.stats.nonfinite.gas, 0u);
    EXPECT_EQ(r.stats.nonfinite.shading, 0u);  // replaced at the term: nothing left for the pixel
    expect_all_finite(r.image);
}

TEST(NonFinite, NaNBackgroundIsCountedAtThePixel) {
    // Materials are clamped to [0,1] when looked up (NaN -> 0, warned of by the reader), so a value
    // that reaches the pixel unchecked comes from elsewhere: here the background a mirror sees.
    Material mirror;
    mirror.reflectivity = 1.0;
    FlatScene scene = lit_sphere(mirror, white_directional());
    Result r = render(scene, Vec3(0.0, kNaN, 0.0));
    EXPECT_GT(r.stats.nonfinite.shading, 0u);
    EXPECT_EQ(r.stats.nonfinite.light, 0u);
    EXPECT_EQ(r.stats.nonfinite.gas, 0u);
    expect_all_finite(r.image);
    EXPECT_EQ(r.image.pixel(0, 0)[1], 0.0f);  // written as 0, as documented
}

TEST(NonFinite, NaNLightInGasIsCountedAsGas) {
    // The light's NaN colour enters the gas's in-scattering integral: the gas result is what is not
    // finite, counted once per gas integral.
    FlatScene scene = empty_scene();
    Material m;
    m.density = 1.0;
    m.albedo = Vec3(0.5);
    m.emission = Vec3(0.0);
    add_sphere(scene, Vec3(0.0), 1.0, add_shading(scene, m));
    scene.spheres.back().gas = true;
    Light l = white_directional();
    l.color = Vec3(1.0, kNaN, 1.0);
    add_light(scene, l);
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 5.0), 0.6));
    Result r = render(scene);
    EXPECT_GT(r.stats.nonfinite.gas, 0u);
    EXPECT_LE(r.stats.nonfinite.gas, uint64_t(kSize * kSize));  // one per camera ray at most
    EXPECT_EQ(r.stats.nonfinite.shading, 0u);
    expect_all_finite(r.image);
}

}  // namespace
}  // namespace vr
