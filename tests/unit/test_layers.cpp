// X3D Layering and Layout (clauses 35, 36), ClipPlane (11.4.1) and LocalFog (24.4.3) through the
// whole pipeline, against values worked out by hand (docs/rendering.md "Layers", "ClipPlane").
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/render.h"
#include "scene/build.h"

namespace vr {
namespace {

struct Flat {
    FlatScene flat;
    std::string messages;
    size_t warnings = 0;
};

// `text` read, built and flattened for a width x height image.
Flat flatten_text(const std::string& text, int width = 0, int height = 0) {
    LoadedScene loaded = load_scene_text(text, "test.x3dv");
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.image_width = width;
    fo.image_height = height;
    FlattenStats stats;
    Flat out;
    out.flat = flatten_scene(scene, fo, diagnostics, stats);
    out.messages = diagnostics.format(loaded.sources);
    out.warnings = diagnostics.warning_count();
    return out;
}

Image render(const FlatScene& flat, int width, int height) {
    RenderOptions o;
    o.width = width;
    o.height = height;
    o.threads = 2;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(flat, o, camera, error)) << error;
    RenderStats rs;
    return render_image(flat, camera, o, nullptr, rs);
}

Vec3 pixel(const Image& im, int x, int y) {
    const float* p = &im.rgba[4 * (size_t(y) * size_t(im.width) + size_t(x))];
    return Vec3(p[0], p[1], p[2]);
}

const std::string kHeader = "#X3D V3.3 utf8\n";
// Unlit colours: no Material, or only an emissive one, so that a pixel is exactly the colour.
std::string emissive(const std::string& rgb) {
    return "appearance Appearance { material Material { diffuseColor 0 0 0 emissiveColor " + rgb +
           " } }";
}

// ---------------------------------------------------------------------------------------------
// ClipPlane

// A unit sphere at the origin under a ClipPlane that keeps z <= 0.5, the plane given in a
// Transform's coordinates (z' = z - 0.5 <= 0) to test its mapping to world space.
const std::string kCutSphere = kHeader +
                               "Transform { translation 0 0 0.5 children [\n"
                               "  ClipPlane { plane 0 0 -1 0 }\n"
                               "  Transform { translation 0 0 -0.5 children Shape { " +
                               emissive("1 1 1") +
                               " geometry Sphere { } } } ] }\n"
                               "Transform { translation 3 0 0 children Shape { " +
                               emissive("1 1 1") + " geometry Sphere { } } }\n";

TEST(ClipPlane, CutSphereHitsTheClosedForm) {
    const Flat f = flatten_text(kCutSphere);
    EXPECT_EQ(f.warnings, 0u) << f.messages;
    ASSERT_EQ(f.flat.spheres.size(), 2u);
    Accel accel;
    accel.build(f.flat, 1);
    // Rays along -z from z = 5 at (x, y): the sphere's roots are z = +-h, h = sqrt(1 - r^2). The
    // near one is kept when h <= 0.5 (r^2 >= 0.75), else the far one, the inside of the cut.
    for (double x : {0.0, 0.3, 0.6, 0.8, 0.9, 0.99}) {
        const double y = 0.1;
        const double r2 = x * x + y * y;
        Ray ray{Vec3(x, y, 5.0), Vec3(0.0, 0.0, -1.0), kInf};
        Hit hit;
        if (r2 >= 1.0) {
            EXPECT_FALSE(accel.intersect(ray, hit)) << x;
            continue;
        }
        ASSERT_TRUE(accel.intersect(ray, hit)) << x;
        const double h = std::sqrt(1.0 - r2);
        const double expected = h <= 0.5 ? 5.0 - h : 5.0 + h;
        // The sphere root's relative error is a few ulps of the distance 5.
        EXPECT_NEAR(hit.t, expected, 1e-12) << x;
    }
    // The unclipped sphere beside it keeps its near root.
    Ray ray{Vec3(3.0, 0.0, 5.0), Vec3(0.0, 0.0, -1.0), kInf};
    Hit hit;
    ASSERT_TRUE(accel.intersect(ray, hit));
    EXPECT_NEAR(hit.t, 4.0, 1e-12);
}

TEST(ClipPlane, ShadowsPassWhereTheSphereIsCut) {
    const Flat f = flatten_text(kCutSphere);
    Accel accel;
    accel.build(f.flat, 1);
    // A segment along x through the sphere at height z: it crosses the surface at z = 0.8 only
    // where z > 0.5 (cut away), at z = 0.2 where it is kept.
    Ray above{Vec3(-2.0, 0.0, 0.8), Vec3(1.0, 0.0, 0.0), 4.0};
    Ray below{Vec3(-2.0, 0.0, 0.2), Vec3(1.0, 0.0, 0.0), 4.0};
    EXPECT_EQ(accel.transmittance(above), 1.0);
    EXPECT_EQ(accel.transmittance(below), 0.0);
}

TEST(ClipPlane, PixelsShowTheSphereWhereTheClosedFormSays) {
    // Orthographic, 2 units across 40 pixels: pixel centres at x = -1 + (i + 0.5) / 20.
    const std::string text = kHeader +
                             "OrthoViewpoint { position 0 0 5 fieldOfView [-1 -1 1 1] }\n"
                             "ClipPlane { plane 1 0 0 0 }\n"  // keeps x >= 0
                             "Shape { geometry Sphere { } }\n";
    const Flat f = flatten_text(text);
    const Image im = render(f.flat, 40, 40);
    for (int j = 0; j < 40; ++j)
        for (int i = 0; i < 40; ++i) {
            const double x = -1.0 + (i + 0.5) / 20.0, y = 1.0 - (j + 0.5) / 20.0;
            const bool sphere = x >= 0.0 && x * x + y * y < 1.0;
            // Unlit white (no Material) on a black background.
            EXPECT_EQ(pixel(im, i, j).x, sphere ? 1.0f : 0.0f) << i << " " << j;
        }
}

TEST(ClipPlane, DisabledOrAbsentAddsNothing) {
    const Flat f =
        flatten_text(kHeader + "ClipPlane { enabled FALSE }\nShape { geometry Sphere {} }\n");
    EXPECT_FALSE(f.flat.any_clip_planes());
    EXPECT_EQ(f.flat.scopes.size(), 1u);
}

// ---------------------------------------------------------------------------------------------
// LocalFog

TEST(LocalFog, FogsOnlyItsParentGroup) {
    // Two unlit white quads 5 units from an orthographic camera; only the left one's group holds a
    // LocalFog (linear, range 25): factor (25 - 5) / 25 = 0.8, colour 0.8 white + 0.2 blue.
    const std::string quad =
        "Shape { geometry IndexedFaceSet { coord Coordinate { point [%] } "
        "coordIndex [0 1 2 3] } }";
    auto at = [&](const std::string& pts) {
        std::string q = quad;
        q.replace(q.find('%'), 1, pts);
        return q;
    };
    const std::string text =
        kHeader + "OrthoViewpoint { position 0 0 5 fieldOfView [-2 -1 2 1] }\n" +
        "Group { children [ LocalFog { color 0 0 1 visibilityRange 25 } " +
        at("-2 -1 0, 0 -1 0, 0 1 0, -2 1 0") + " ] }\n" + at("0 -1 0, 2 -1 0, 2 1 0, 0 1 0") + "\n";
    const Flat f = flatten_text(text);
    EXPECT_EQ(f.warnings, 0u) << f.messages;
    const Image im = render(f.flat, 40, 20);
    const Vec3 left = pixel(im, 5, 10), right = pixel(im, 35, 10);
    // Float image of a double computation: a few ulps.
    EXPECT_NEAR(left.x, 0.8, 1e-6);
    EXPECT_NEAR(left.z, 1.0, 1e-6);
    EXPECT_EQ(right, Vec3(1.0));
}

// ---------------------------------------------------------------------------------------------
// Layers

const std::string kRedSphere = "Shape { " + emissive("1 0 0") + " geometry Sphere { } }";

TEST(Layers, WholeWorldInOneLayerRendersAsWithoutIt) {
    // Titania and X_ITE's editors put the whole scene in a LayerSet: it draws as the plain scene.
    const std::string world = "Viewpoint { position 0 0 10 }\n" + kRedSphere + "\n";
    const Flat plain = flatten_text(kHeader + world);
    const Flat layered =
        flatten_text(kHeader + "LayerSet { activeLayer 1 order [1] layers [ Layer { children [\n" +
                     world + "] } ] }\n");
    EXPECT_EQ(layered.warnings, 0u) << layered.messages;
    EXPECT_TRUE(layered.flat.layers.empty());
    const Image a = render(plain.flat, 32, 24), b = render(layered.flat, 32, 24);
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    EXPECT_TRUE(std::equal(a.rgba.begin(), a.rgba.end(), b.rgba.begin()));
    EXPECT_EQ(pixel(b, 16, 12), Vec3(1.0, 0.0, 0.0));
}

TEST(Layers, LaterLayerIsDrawnOverEvenWhenFarther) {
    // Layer 0: a red unit sphere 10 from its camera (angular radius asin(1/10) = 0.1002). Layer 1:
    // a green sphere of radius 0.5 at distance 30 (angular radius 0.0167), behind the red one in
    // depth, drawn over it all the same. fieldOfView 0.4 over 40 pixels: 0.01 rad a pixel about.
    const std::string text = kHeader + "Viewpoint { position 0 0 10 fieldOfView 0.4 }\n" +
                             kRedSphere +
                             "\nLayerSet { order [0 1] layers [ Layer { children [\n"
                             "  Viewpoint { position 0 0 10 fieldOfView 0.4 }\n"
                             "  Transform { translation 0 0 -20 children Shape { " +
                             emissive("0 1 0") + " geometry Sphere { radius 0.5 } } } ] } ] }\n";
    const Flat f = flatten_text(text);
    EXPECT_EQ(f.warnings, 0u) << f.messages;
    ASSERT_EQ(f.flat.layers.size(), 2u);
    const Image im = render(f.flat, 40, 40);
    EXPECT_EQ(pixel(im, 20, 20), Vec3(0.0, 1.0, 0.0));  // centre: the far green sphere on top
    EXPECT_EQ(pixel(im, 27, 20), Vec3(1.0, 0.0, 0.0));  // ~0.07 rad: red only
    EXPECT_EQ(pixel(im, 1, 1), Vec3(0.0));              // neither: layer 0's (black) background
}

TEST(Layers, ViewportClipsTheLayerToItsRectangle) {
    // Layer 0: a red Background. Layer 1: a green emissive box filling its view, clipped to
    // clipBoundary [0.25 0.75 0.5 1] of a 64 x 32 image: pixels x in [16, 48), rows [0, 16).
    const std::string text =
        kHeader +
        "Background { skyColor 1 0 0 }\n"
        "LayerSet { order [0 1] layers [ Layer { viewport Viewport { clipBoundary "
        "[0.25 0.75 0.5 1] } children [\n"
        "  OrthoViewpoint { position 0 0 5 fieldOfView [-1 -1 1 1] }\n"
        "  Shape { " +
        emissive("0 1 0") + " geometry Box { size 10 10 1 } } ] } ] }\n";
    const Flat f = flatten_text(text, 64, 32);
    EXPECT_EQ(f.warnings, 0u) << f.messages;
    const Image im = render(f.flat, 64, 32);
    for (int j = 0; j < 32; ++j)
        for (int i = 0; i < 64; ++i) {
            const bool inside = i >= 16 && i < 48 && j < 16;
            EXPECT_EQ(pixel(im, i, j), inside ? Vec3(0, 1, 0) : Vec3(1, 0, 0)) << i << " " << j;
        }
}

TEST(Layers, LayoutPlacesAQuadInTheTopLeftQuarter) {
    // A LayoutLayer (default OrthoViewpoint: -1..1 across the 32-pixel height, so the 64 x 32
    // viewport is 4 x 2 units). Layout size 0.5 0.5 FRACTION, align LEFT TOP, scaleMode FRACTION:
    // a rectangle of 2 x 1 units centred at (-1, 0.5), whose unit square -0.5..0.5 is the
    // rectangle itself: x in [-2, 0], y in [0, 1], pixels x < 32, rows < 16.
    const std::string text =
        kHeader +
        "LayerSet { order [0 1] layers [ LayoutLayer { layout Layout { align [\"LEFT\" \"TOP\"] "
        "size [0.5 0.5] sizeUnits [\"FRACTION\" \"FRACTION\"] scaleMode [\"FRACTION\" "
        "\"FRACTION\"] } children Shape { geometry IndexedFaceSet { coord Coordinate { point "
        "[-0.5 -0.5 0, 0.5 -0.5 0, 0.5 0.5 0, -0.5 0.5 0] } coordIndex [0 1 2 3] } } } ] }\n";
    const Flat f = flatten_text(text, 64, 32);
    EXPECT_EQ(f.warnings, 0u) << f.messages;
    const Image im = render(f.flat, 64, 32);
    for (int j = 0; j < 32; ++j)
        for (int i = 0; i < 64; ++i) {
            const bool inside = i < 32 && j < 16;
            EXPECT_EQ(pixel(im, i, j), inside ? Vec3(1.0) : Vec3(0.0)) << i << " " << j;
        }
}

TEST(Layers, BadOrderIndexWarnsAndTheRestDraws) {
    const Flat f = flatten_text(kHeader + "LayerSet { order [0 5 1] layers [ Layer { children " +
                                kRedSphere + " } ] }\n");
    EXPECT_NE(f.messages.find("order names layer 5"), std::string::npos) << f.messages;
    ASSERT_EQ(f.flat.layers.size(), 2u);
}

}  // namespace
}  // namespace vr

namespace vr {
namespace {

TEST(Layers, XmlLayerAndViewportTakeTheirDefaultContainerFields) {
    // X3D XML: <Layer> goes to LayerSet.layers, <Viewport> to Layer.viewport, <Layout> to
    // LayoutGroup.layout without a containerField attribute (the X3D schema's defaults).
    const std::string text =
        "<?xml version='1.0' encoding='UTF-8'?>\n<X3D profile='Full' version='3.3'><Scene>\n"
        "<LayerSet order='0 1'><Layer><Viewport clipBoundary='0 0.5 0 1'/>\n"
        "<LayoutGroup><Layout size='1 1'/><Shape><Sphere/></Shape></LayoutGroup>\n"
        "</Layer></LayerSet></Scene></X3D>\n";
    LoadedScene loaded = load_scene_text(text, "test.x3d");
    ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    EXPECT_EQ(loaded.diagnostics.warning_count(), 0u) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    EXPECT_EQ(diagnostics.warning_count(), 0u) << diagnostics.format(loaded.sources);
    ASSERT_EQ(scene.layers.size(), 2u);
    EXPECT_EQ(scene.layers[1].clip[1], 0.5);
    EXPECT_EQ(scene.layouts.size(), 1u);
}

}  // namespace
}  // namespace vr
