// Telephoto views (docs/manual.md, Camera: every fieldOfView in (0, pi) is valid, however small): a
// sphere whose silhouette must fall at a computed pixel radius, rendered through the whole pipeline
// (parser, flatten, camera, tracer), at fields of view down to 3e-8 rad.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/render.h"
#include "scene/build.h"

namespace vr {
namespace {

constexpr int kSize = 32;  // even: pixel centres sit at half-integer offsets from the axis
constexpr double kEdgePixels = 10.0;  // the silhouette's radius in pixels, in the image plane

struct Rendered {
    Image image;
    Diagnostics diagnostics;
};

Rendered render_text(const std::string& text) {
    Rendered out;
    LoadedScene loaded = load_scene_text(text, "telephoto.wrl");
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Scene scene = build_scene(loaded, out.diagnostics);
    FlattenStats stats;
    FlatScene flat = flatten_scene(scene, FlattenOptions{}, out.diagnostics, stats);
    RenderOptions options;
    options.width = options.height = kSize;
    options.threads = 1;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(flat, options, camera, error)) << error;
    RenderStats render_stats;
    out.image = render_image(flat, camera, options, nullptr, render_stats);
    return out;
}

std::string g(double v) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.17g", v);
    return buffer;
}

// A white unlit-looking sphere (emissive, no headlight) of radius r at the origin on black.
std::string sphere_scene(const std::string& header, const std::string& viewpoint, double r) {
    return header + "NavigationInfo { headlight FALSE }\n" + viewpoint +
           "Shape { appearance Appearance { material Material { diffuseColor 0 0 0 emissiveColor 1 "
           "1 1 } }\n"
           "        geometry Sphere { radius " +
           g(r) + " } }\n";
}

// Pixel (i, j) is covered when its centre lies inside a circle of kEdgePixels pixels about the
// image centre. 4 rho^2 = (2a+1)^2 + (2b+1)^2 is 2 mod 8 and 4 * 100 is 0 mod 8, so no centre lies
// on the circle: the nearest ones are at rho^2 = 98.5 and 100.5, half a percent away.
void expect_disc(const Image& image, const std::string& what) {
    int wrong = 0;
    for (int j = 0; j < kSize; ++j) {
        for (int i = 0; i < kSize; ++i) {
            const double x = i + 0.5 - 0.5 * kSize, y = j + 0.5 - 0.5 * kSize;
            const bool inside = x * x + y * y < kEdgePixels * kEdgePixels;
            const float red = image.pixel(i, j)[0];
            if ((red > 0.5f) != inside) ++wrong;
        }
    }
    EXPECT_EQ(wrong, 0) << what;
}

TEST(Telephoto, PerspectiveSilhouetteAtTheComputedPixel) {
    const double distance = 1e4;
    for (double fov : {1e-2, 1e-5, 3e-8}) {
        // The ray through image point rho (pixels) leaves the axis at tan(theta) = rho * pixel,
        // with pixel = 2 tan(fov/2) / size; it grazes a sphere of radius D sin(theta) at distance
        // D.
        const double pixel = 2.0 * std::tan(0.5 * fov) / kSize;
        const double r = distance * std::sin(std::atan(kEdgePixels * pixel));
        const std::string vp =
            "Viewpoint { position 0 0 " + g(distance) + " fieldOfView " + g(fov) + " }\n";
        Rendered out = render_text(sphere_scene("#VRML V2.0 utf8\n", vp, r));
        EXPECT_EQ(out.diagnostics.all().size(), 0u)
            << "fov " << fov << ": a valid fieldOfView warns";
        expect_disc(out.image, "fov " + g(fov));
    }
}

TEST(Telephoto, OrthoSilhouetteAtTheComputedPixel) {
    for (double half : {1e-2, 1e-5, 3e-8}) {
        // The window [-half, half]^2 spans 32 pixels; a ray at rho pixels is rho * 2 half / 32 off
        // the axis, so a sphere of radius 10 such pixels has its edge at rho = 10.
        const double r = kEdgePixels * 2.0 * half / kSize;
        const std::string vp = "OrthoViewpoint { position 0 0 10000 fieldOfView [" + g(-half) +
                               " " + g(-half) + " " + g(half) + " " + g(half) + "] }\n";
        Rendered out = render_text(sphere_scene("#X3D V3.0 utf8\n", vp, r));
        EXPECT_EQ(out.diagnostics.all().size(), 0u) << "half extent " << half;
        expect_disc(out.image, "ortho half extent " + g(half));
    }
}

TEST(Telephoto, OnlyValuesOutsideZeroPiWarnAndWithPlainNumbers) {
    for (auto [fov, expected] :
         {std::pair{0.005, ""}, std::pair{3.2e-8, ""},
          std::pair{0.0, "fieldOfView 0 lies outside (0, pi); using 0.785398"},
          std::pair{4.0, "fieldOfView 4 lies outside (0, pi); using 3.13159"}}) {
        Rendered out = render_text(
            sphere_scene("#VRML V2.0 utf8\n",
                         "Viewpoint { position 0 0 10 fieldOfView " + g(fov) + " }\n", 1.0));
        std::string messages;
        for (const Diagnostic& d : out.diagnostics.all()) messages += d.message + "\n";
        if (std::string(expected).empty())
            EXPECT_EQ(messages, "") << fov;
        else
            EXPECT_NE(messages.find(expected), std::string::npos) << messages;
    }
}

}  // namespace
}  // namespace vr
