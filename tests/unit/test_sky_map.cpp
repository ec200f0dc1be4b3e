// --sky FILE (docs/rendering.md, Soft light with error bounds): the equirectangular mapping and its
// filter, files written and read back through the image modules, the sky-light integral against
// closed forms, and the map as the background.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>

#include "image/image.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/render.h"
#include "render/sky_area_light.h"
#include "render/sky_map.h"
#include "test_render_util.h"

namespace vr {
namespace {

namespace fs = std::filesystem;
using testing::add_shading;
using testing::add_sphere;
using testing::empty_scene;

// An image whose texel (i, j) is `f(i, j)`.
template <class F>
Image make_image(int w, int h, F&& f) {
    Image image(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const Vec3 c = f(i, j);
            float* px = image.pixel(i, j);
            px[0] = float(c.x), px[1] = float(c.y), px[2] = float(c.z), px[3] = 1.0f;
        }
    return image;
}

// The unit direction of map coordinates (u, v): the inverse of sky_map_uv, by hand.
Vec3 direction_of(double u, double v) {
    const double phi = (u - 0.5) * 2.0 * kPi, polar = v * kPi;
    return Vec3(std::sin(polar) * std::sin(phi), std::cos(polar), -std::sin(polar) * std::cos(phi));
}

// A texel colour that differs between all texels of a small map.
Vec3 distinct(int i, int j) { return Vec3(0.1 * i, 0.05 * j + 0.01, 0.3 + 0.01 * (i * j)); }

struct TempFolder {
    fs::path path = fs::temp_directory_path() / ("vrmlray_sky_" + std::to_string(::getpid()));
    TempFolder() { fs::create_directories(path); }
    ~TempFolder() { fs::remove_all(path); }
};

TEST(SkyMap, ZenithIsTheTopRowAndMinusZTheMiddleColumn) {
    double u, v;
    const struct {
        Vec3 w;
        double u, v;
    } cases[] = {{{0, 0, -1}, 0.5, 0.5},
                 {{1, 0, 0}, 0.75, 0.5},
                 {{-1, 0, 0}, 0.25, 0.5},
                 {{0, 0, 1}, 0.0, 0.5},
                 {{0, 1, 0}, 0.5, 0.0},
                 {{0, -1, 0}, 0.5, 1.0},
                 {{0, 0.5 * std::sqrt(2.0), -0.5 * std::sqrt(2.0)}, 0.5, 0.25}};
    for (const auto& c : cases) {
        sky_map_uv(c.w, u, v);
        // A few ulps of atan2 and acos. At the poles every u is the same point.
        if (std::abs(c.w.y) < 1.0) {
            EXPECT_NEAR(u, c.u, 1e-15) << c.w.x << " " << c.w.z;
        }
        EXPECT_NEAR(v, c.v, 1e-15) << c.w.x << " " << c.w.y << " " << c.w.z;
    }
}

TEST(SkyMap, TexelCentresGiveTheTexelAndBilinearInBetween) {
    const int w = 8, h = 4;
    const SkyMap map(make_image(w, h, distinct));
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const Vec3 got = map.radiance(direction_of((i + 0.5) / w, (j + 0.5) / h));
            // Float texels (~3e-8 of these values); the direction's round trip costs ~1e-15.
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], distinct(i, j)[c], 1e-7) << i << j;
        }
    // Half-way between columns 2 and 3 of row 1, and across the seam between columns 7 and 0.
    const Vec3 mid = map.radiance(direction_of(3.0 / w, 1.5 / h));
    const Vec3 seam = map.radiance(direction_of(0.0, 1.5 / h));
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(mid[c], 0.5 * (distinct(2, 1)[c] + distinct(3, 1)[c]), 1e-7);
        EXPECT_NEAR(seam[c], 0.5 * (distinct(7, 1)[c] + distinct(0, 1)[c]), 1e-7);
    }
    // Above the top row's centres the value is the top row's (clamped, not wrapped over the pole).
    const Vec3 top = map.radiance(direction_of(2.5 / w, 0.1 / h));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(top[c], distinct(2, 0)[c], 1e-7);
    EXPECT_EQ(map.radiance(Vec3(0.0)), Vec3(0.0));
}

TEST(SkyMap, ExrAndHdrFilesReadBackAsTheirTexels) {
    TempFolder dir;
    // Powers of two: exact in half floats (EXR) and in RGBE (HDR), whose mantissas are 8 bits.
    auto texel = [](int i, int j) { return Vec3(0.25 * (i + 1), 0.5 * (j + 1), 2.0); };
    const Image image = make_image(4, 2, texel);
    for (const char* name : {"sky.exr", "sky.hdr"}) {
        const std::string path = (dir.path / name).string();
        std::string error;
        ASSERT_TRUE(write_image(path, image, false, error)) << error;
        std::shared_ptr<const SkyMap> map;
        ASSERT_TRUE(load_sky_map(path, map, error)) << error;
        ASSERT_EQ(map->width(), 4);
        ASSERT_EQ(map->height(), 2);
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 4; ++i) EXPECT_EQ(map->texel(i, j), texel(i, j)) << name;
        EXPECT_EQ(map->lowest(), Vec3(0.25, 0.5, 2.0));
        EXPECT_EQ(map->highest(), Vec3(1.0, 1.0, 2.0));
    }
    std::shared_ptr<const SkyMap> map;
    std::string error;
    EXPECT_FALSE(load_sky_map((dir.path / "missing.exr").string(), map, error));
    EXPECT_NE(error.find("missing.exr"), std::string::npos) << error;
}

TEST(SkyMap, BadTexelsBecomeZero) {
    const SkyMap map(make_image(2, 1, [](int i, int) {
        return i == 0 ? Vec3(-1.0, std::nan(""), 0.5) : Vec3(kInf, 1.0, 0.25);
    }));
    EXPECT_EQ(map.fixed(), 3u);
    EXPECT_EQ(map.texel(0, 0), Vec3(0.0, 0.0, 0.5));
    EXPECT_EQ(map.texel(1, 0), Vec3(0.0, 1.0, 0.25));
}

// ----- The sky-light integral -----

struct OneSphere {
    FlatScene scene = empty_scene();
    Accel accel;
    OneSphere(const Vec3& c, double r) {
        add_sphere(scene, c, r, add_shading(scene, Material{}));
        accel.build(scene, 1);
    }
};

const double kTolerances[] = {1e-2, 1e-3};

TEST(SkyMap, ConstantMapIsTheSkyColourTimesTheOcclusion) {
    // A constant map must light as --sky R,G,B does: R,G,B times A(p), to the tolerance.
    const Vec3 colour(0.3, 0.6, 0.9);
    const OneSphere s(Vec3(0.4, 2.0, 0.1), 0.8);
    RenderOptions with_map, with_colour;
    with_map.sky_map =
        std::make_shared<const SkyMap>(make_image(16, 8, [&](int, int) { return colour; }));
    with_colour.sky = colour;
    for (double e : kTolerances) {
        with_map.light_tolerance = with_colour.light_tolerance = e;
        const SoftLighting a(s.scene, s.accel, nullptr, with_map);
        const SoftLighting b(s.scene, s.accel, nullptr, with_colour);
        for (const Vec3 n : {Vec3(0, 1, 0), glm::normalize(Vec3(0.3, 1, -0.2))}) {
            SoftLightCounts counts;
            const Vec3 got = a.sky_radiance(Vec3(0.0), Vec3(1e-15), n, n, counts);
            const Vec3 want = colour * b.sky_visibility(Vec3(0.0), Vec3(1e-15), n, n, counts);
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], e * colour[c]);
        }
    }
}

TEST(SkyMap, TwoColourMapUnderOneSphereIsTheClosedForm) {
    // Upper half `up`, lower half `down`. A surface tilted by alpha from +Y sees the
    // cosine-weighted share (1 + cos alpha) / 2 of the upper half and (1 - cos alpha) / 2 of the
    // lower (the sky view factor); a sphere wholly above both the surface and the horizon takes
    // (r/d)^2 cos theta from the upper share (docs/rendering.md, Soft light with error bounds's
    // closed form).
    const Vec3 up(0.2, 0.5, 1.0), down(0.4, 0.3, 0.1);
    auto map = std::make_shared<const SkyMap>(
        make_image(64, 512, [&](int, int j) { return j < 256 ? up : down; }));
    struct Case {
        double alpha, r, d, theta;
    };
    for (const Case& k : {Case{0.0, 0.5, 2.0, 0.3}, Case{0.6, 0.3, 1.5, 0.4},
                          Case{1.0, 0.8, 3.0, 0.7}, Case{1.3, 0.2, 1.0, 1.0}}) {
        const Vec3 n(std::sin(k.alpha), std::cos(k.alpha), 0.0);
        // The centre turned by theta from n towards +Y, and a little out of the tilt's plane.
        const double beta = k.alpha - k.theta;
        const Vec3 c = k.d * Vec3(std::sin(beta), std::cos(beta), 0.0);
        ASSERT_GT(std::cos(beta), k.r / k.d);  // wholly above the horizon
        const OneSphere s(c, k.r);
        const double blocked = (k.r / k.d) * (k.r / k.d) * std::cos(k.theta);
        const double up_share = 0.5 * (1.0 + std::cos(k.alpha)) - blocked;
        const double down_share = 0.5 * (1.0 - std::cos(k.alpha));
        for (double e : kTolerances) {
            RenderOptions o;
            o.sky_map = map;
            o.light_tolerance = e;
            const SoftLighting soft(s.scene, s.accel, nullptr, o);
            SoftLightCounts counts;
            const Vec3 got = soft.sky_radiance(Vec3(0.0), Vec3(1e-15), n, n, counts);
            EXPECT_GT(counts.sampled_points, 0u);  // the non-constant part is sampled
            for (int ch = 0; ch < 3; ++ch) {
                const double want = up[ch] * up_share + down[ch] * down_share;
                // The bound: E times the channel's largest texel, at 99% per point (the
                // equator's bilinear band is symmetric about the horizon: ~1e-6 here).
                EXPECT_NEAR(got[ch], want, e * std::max(up[ch], down[ch]))
                    << "alpha " << k.alpha << " e " << e << " channel " << ch;
            }
        }
    }
}

// ----- The map as the background -----

// A one-pixel render looking along `view` of a scene without geometry.
Vec3 background_pixel(FlatScene scene, const RenderOptions& base, const Vec3& view) {
    RenderOptions o = base;
    o.width = o.height = 1;
    o.threads = 1;
    o.camera_position = Vec3(0.0);
    o.look_at = view;
    o.up = std::abs(view.y) > 0.9 ? Vec3(0.0, 0.0, -1.0) : Vec3(0.0, 1.0, 0.0);
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(scene, o, camera, error)) << error;
    RenderStats stats;
    const Image image = render_image(scene, camera, o, nullptr, stats, nullptr);
    const float* px = image.pixel(0, 0);
    return Vec3(px[0], px[1], px[2]);
}

TEST(SkyMap, BackgroundShowsTheTexelsUnlessTheSceneHasABackground) {
    const int w = 8, h = 4;
    RenderOptions o;
    o.sky_map = std::make_shared<const SkyMap>(make_image(w, h, distinct));
    FlatScene scene = empty_scene();
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0), 0.5));
    // The view through texel (5, 1)'s centre; -Z at the middle of rows 1 and 2, columns 3 and 4;
    // straight along +X: the middle of column 5 and 6 (u = 0.75) between rows 1 and 2.
    const Vec3 at_51 = background_pixel(scene, o, direction_of(5.5 / w, 1.5 / h));
    const Vec3 ahead = background_pixel(scene, o, Vec3(0, 0, -1));
    const Vec3 right = background_pixel(scene, o, Vec3(1, 0, 0));
    for (int c = 0; c < 3; ++c) {
        // Float pixels: 1e-6 of values below 1.
        EXPECT_NEAR(at_51[c], distinct(5, 1)[c], 1e-6);
        EXPECT_NEAR(
            ahead[c],
            0.25 * (distinct(3, 1)[c] + distinct(4, 1)[c] + distinct(3, 2)[c] + distinct(4, 2)[c]),
            1e-6);
        EXPECT_NEAR(
            right[c],
            0.25 * (distinct(5, 1)[c] + distinct(6, 1)[c] + distinct(5, 2)[c] + distinct(6, 2)[c]),
            1e-6);
    }
    // A bound Background wins over the map, and --background over both.
    scene.background.present = true;
    scene.background.sky_colors = {Vec3(0.7, 0.1, 0.2)};
    EXPECT_EQ(background_pixel(scene, o, Vec3(0, 0, -1)), Vec3(float(0.7), float(0.1), float(0.2)));
    scene.background.present = false;
    o.background = Vec3(0.5);
    EXPECT_EQ(background_pixel(scene, o, Vec3(0, 0, -1)), Vec3(0.5));
}

}  // namespace
}  // namespace vr
