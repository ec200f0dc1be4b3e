// Alpha (docs/manual.md, render): 1 minus the weight with which the background reaches the pixel,
// computed from optical depth with expm1 so that dense gas gives 1 and ultrathin gas keeps its
// digits; with options.alpha the colour leaves the background out, so that compositing gives the
// opaque colour.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <tuple>

#include "flatten/flatten.h"
#include "image/image.h"
#include "parser/load.h"
#include "render/accel.h"
#include "render/integrator.h"
#include "render/render.h"
#include "scene/build.h"
#include "test_render_util.h"

namespace vr {
namespace {

using testing::add_shading;
using testing::add_sphere;
using testing::empty_scene;

// A gas sphere of radius 1 and extinction sigma at the origin, optionally behind a see-through
// sheet of transparency kt at z = 2, seen from z = 3 on a grey background.
FlatScene gas_scene(double sigma, double kt = -1.0) {
    FlatScene scene = empty_scene();
    Material gas;
    gas.density = sigma;
    gas.albedo = Vec3(0.0);
    gas.emission = Vec3(0.5, 0.25, 1.0);
    add_sphere(scene, Vec3(0.0), 1.0, add_shading(scene, gas));
    scene.spheres.back().gas = true;
    if (kt >= 0.0) {
        Material sheet;
        sheet.transparency = kt;
        sheet.diffuse = Vec3(0.0);
        sheet.emissive = Vec3(0.2);
        testing::add_quad(scene, Vec3(-5, -5, 2), Vec3(5, -5, 2), Vec3(5, 5, 2), Vec3(-5, 5, 2),
                          add_shading(scene, sheet));
    }
    scene.background.present = true;
    scene.background.sky_colors = {Vec3(0.3, 0.6, 0.9)};
    scene.viewpoints.push_back(testing::look_from(Vec3(0.0, 0.0, 3.0), 1.2));  // corners miss
    return scene;
}

struct Traced {
    SampleValue centre;  // the camera ray through the sphere's centre
    SampleValue miss;    // a camera ray that meets nothing
};

Traced trace(const FlatScene& scene, bool alpha) {
    RenderOptions options;
    options.width = options.height = 9;
    options.alpha = alpha;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(scene, options, camera, error)) << error;
    Accel accel;
    accel.build(scene, 1);
    GasVolume gas;
    gas.build(scene, options);
    const Integrator integrator(scene, accel, camera, options, &gas);
    const CameraRays rays(camera, options.width, options.height);
    RayCounters counters;
    Traced t;
    t.centre = integrator.trace_camera_ray(rays(4.5, 4.5), counters);
    t.miss = integrator.trace_camera_ray(rays(0.0, 0.0), counters);
    return t;
}

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

TEST(Alpha, DenseGasIsOpaque) {
    // sigma r = 1e3: T = exp(-2000) underflows to 0; the background is hidden, alpha is 1 (it was
    // 0: a fully absorbed path kept the default "background reaches the pixel").
    const Traced t = trace(gas_scene(1000.0), false);
    EXPECT_EQ(t.centre.alpha, 1.0);
    EXPECT_EQ(t.miss.alpha, 0.0);
    // Through the float image too.
    FlatScene scene = gas_scene(1000.0);
    RenderOptions options;
    options.width = options.height = 9;
    Camera camera;
    std::string error;
    ASSERT_TRUE(make_camera(scene, options, camera, error));
    RenderStats stats;
    const Image image = render_image(scene, camera, options, nullptr, stats);
    EXPECT_EQ(image.pixel(4, 4)[3], 1.0f);
    EXPECT_EQ(image.pixel(0, 0)[3], 0.0f);
}

TEST(Alpha, UltrathinGasKeepsItsDigits) {
    // sigma r = 1e-14: the chord through the centre has tau = sigma * 2r = 2e-14 (entry and exit at
    // t = 2 and 4, exact in double); alpha = -expm1(-tau). 1 - exp(-tau) is 2.0206e-14, 1% off.
    // 1e-12 relative: tau is a sum of two exact distances times sigma, a few roundings.
    const double tau = 2e-14;
    const Traced t = trace(gas_scene(1e-14), false);
    EXPECT_LT(rel(t.centre.alpha, -std::expm1(-tau)), 1e-12) << t.centre.alpha;
    // Behind a sheet of transparency 0.5: the background weight is 0.5 * exp(-tau), alpha
    // 1 - 0.5 exp(-tau) = 0.5 + 0.5 (-expm1(-tau)).
    const Traced s = trace(gas_scene(1e-14, 0.5), false);
    EXPECT_LT(rel(s.centre.alpha, 0.5 - 0.5 * std::expm1(-tau)), 1e-12) << s.centre.alpha;
    // A fully transparent sheet passes the gas's alpha on unchanged.
    const Traced clear = trace(gas_scene(1e-14, 1.0), false);
    EXPECT_LT(rel(clear.centre.alpha, -std::expm1(-tau)), 1e-12) << clear.centre.alpha;
}

TEST(Alpha, ColourLeavesTheBackgroundOutSoCompositingGivesTheOpaqueColour) {
    const Vec3 sky(0.3, 0.6, 0.9);
    for (double sigma : {1e-14, 0.3, 1000.0}) {
        for (double kt : {-1.0, 0.5}) {
            const Traced opaque = trace(gas_scene(sigma, kt), false);
            const Traced straight = trace(gas_scene(sigma, kt), true);
            EXPECT_EQ(straight.centre.alpha, opaque.centre.alpha);
            // colour + (1 - alpha) * background: a few roundings of order-1 numbers.
            const Vec3 composite = straight.centre.color + (1.0 - straight.centre.alpha) * sky;
            EXPECT_LT(glm::length(composite - opaque.centre.color), 1e-14) << sigma << " " << kt;
            if (kt >= 0.0) continue;  // the sheet covers the whole view
            // A miss is all background: nothing is left of it.
            EXPECT_EQ(straight.miss.color, Vec3(0.0));
            EXPECT_EQ(opaque.miss.color, sky);
        }
    }
}

// The whole chain on real exports, on a coloured background: Jmol's spacefill (opaque atoms),
// PyMOL's spheres in gas mode (their edges give every alpha between 0 and 1) and PyMOL's figure
// with a surface of transparency 0.4. Rendered without and with alpha, written as EXR and PNG and
// read back, the alpha image composited over the background must give the opaque image.
TEST(Alpha, CompositingOverTheBackgroundGivesTheOpaqueImageOnMolecularExports) {
    const Vec3 sky(0.2, 0.4, 0.6);
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("vrmlray_alpha_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    for (auto [name, spheres, min_partial] :
         {std::tuple{"molecular/jmol/pept_spacefill.wrl", SpheresOption::Opaque, 0},
          std::tuple{"molecular/pymol/pept_spheres.wrl", SpheresOption::Gas, 20},
          std::tuple{"vrml97/castle-engine-demo-models/lights_materials/transparent_materials.wrl",
                     SpheresOption::Opaque, 20}}) {
        const std::filesystem::path file = std::filesystem::path(VRMLRAY_CORPUS_DIR) / name;
        if (!std::filesystem::exists(file)) GTEST_SKIP() << "no corpus file " << file;
        Image rendered[2];
        for (int alpha = 0; alpha < 2; ++alpha) {
            LoadedScene loaded = load_scene(file);
            ASSERT_TRUE(loaded.ok());
            Diagnostics diagnostics;
            Scene scene = build_scene(loaded, diagnostics);
            FlattenOptions fo;
            fo.spheres = spheres;
            fo.density = 3.0;
            FlattenStats stats;
            FlatScene flat = flatten_scene(scene, fo, diagnostics, stats);
            RenderOptions options;
            options.width = 64;
            options.height = 48;
            options.spheres = spheres;
            options.density = fo.density;
            options.background = sky;
            options.alpha = alpha == 1;
            options.fit = true;
            Camera camera;
            std::string error;
            ASSERT_TRUE(make_camera(flat, options, camera, error)) << error;
            RenderStats render_stats;
            rendered[alpha] = render_image(flat, camera, options, nullptr, render_stats);
        }
        int partial = 0;  // pixels with 0 < alpha < 1: the test must see some in gas mode
        for (const char* ext : {"exr", "png"}) {
            Image back[2];
            for (int alpha = 0; alpha < 2; ++alpha) {
                const std::string name =
                    (dir / (std::string("pept") + char('0' + alpha) + "." + ext)).string();
                std::string error;
                ASSERT_TRUE(
                    write_image(name, rendered[alpha], WriteOptions{false, alpha == 1}, error))
                    << error;
                ASSERT_TRUE(read_image(name, back[alpha], error)) << error;
            }
            const bool exr = std::string(ext) == "exr";
            double worst = 0.0;
            int overexposed = 0;
            for (size_t p = 0; p < back[0].rgba.size() / 4; ++p) {
                const float* opaque = &back[0].rgba[4 * p];
                const float* with_alpha = &back[1].rgba[4 * p];
                const float* exact = &rendered[1].rgba[4 * p];
                const double a = with_alpha[3];
                if (a > 0.0 && a < 1.0) ++partial;
                // An integer file clamps straight colour to [0, 1]: where the premultiplied colour
                // exceeds alpha (lit gas brighter than white) the composite cannot come back.
                if (!exr && std::max({exact[0], exact[1], exact[2]}) > exact[3]) {
                    ++overexposed;
                    continue;
                }
                for (int c = 0; c < 3; ++c) {
                    // EXR holds premultiplied colour, PNG straight colour.
                    const double colour = exr ? with_alpha[c] : with_alpha[c] * a;
                    const double composite = colour + (1.0 - a) * sky[c];
                    worst = std::max(worst, std::abs(composite - opaque[c]) /
                                                std::max(1.0, std::abs(double(opaque[c]))));
                }
            }
            // EXR: three float roundings (2^-24 each) of values up to about 1, so 1e-6. PNG: the
            // straight colour and alpha are each within half a code of the exact values, so the
            // composite is within (a + 1) / 2 <= 1 code of the exact opaque colour, which is itself
            // stored within half a code: 1.5 codes, plus float slack.
            EXPECT_LT(worst, exr ? 1e-6 : 1.5 / 255 + 1e-6) << ext << " " << name;
            // Most pixels must be checked (pept_spheres in gas mode, headlight plus a light of its
            // own: 628 of 3072 are brighter than white).
            EXPECT_LT(overexposed, int(back[0].rgba.size() / 4 / 3)) << ext << " " << name;
        }
        EXPECT_GE(partial, 2 * min_partial) << name;  // counted over both formats
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace vr
