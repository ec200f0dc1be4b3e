// DEF/USE of meshes: a mesh of 16 triangles or more placed twice or more is stored once in object
// space (FlatScene::prototypes) and placed by instances, each with its own transform and shading;
// the tracer gives each prototype its own BVH. What a user sees must not change: the image is that
// of world-space copies.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <sstream>

#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/accel.h"
#include "render/render.h"
#include "scene/build.h"
#include "scene/transform.h"
#include "test_render_util.h"

namespace vr {
namespace {

// A torus of nu x nv quads (2 nu nv triangles) as an IndexedFaceSet with smooth normals
// (creaseAngle), per-vertex colours and texture coordinates: every per-corner attribute an instance
// must carry.
std::string torus(int nu, int nv) {
    std::ostringstream points, colors, uvs, index;
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const double u = 2.0 * kPi * i / nu, v = 2.0 * kPi * j / nv;
            points << (1.0 + 0.35 * std::cos(v)) * std::cos(u) << ' ' << 0.35 * std::sin(v) << ' '
                   << (1.0 + 0.35 * std::cos(v)) * std::sin(u) << ", ";
            colors << 0.5 + 0.5 * std::cos(u) << ' ' << 0.5 + 0.5 * std::sin(v) << " 0.5, ";
            uvs << double(i) / nu << ' ' << double(j) / nv << ", ";
            const int a = i * nv + j, b = ((i + 1) % nu) * nv + j,
                      c = ((i + 1) % nu) * nv + (j + 1) % nv, d = i * nv + (j + 1) % nv;
            index << a << ' ' << d << ' ' << c << ' ' << b << " -1 ";
        }
    return "IndexedFaceSet { creaseAngle 1.0 coord Coordinate { point [" + points.str() +
           "] } color Color { color [" + colors.str() + "] } texCoord TextureCoordinate { point [" +
           uvs.str() + "] } coordIndex [" + index.str() + "] }";
}

// The placements: a translation, a non-uniform scale, a rotation, a mirror, a tiny and a far one.
const char* const kPlacements[] = {
    "translation -2.2 0 0",
    "translation 2.2 0 0 scale 1 2 0.5",
    "translation 0 2 0 rotation 1 0 0 0.7",
    "translation 0 -2 0 scale -1 1 1",
    "translation 0 0 -2 scale 0.001 0.001 0.001",
    "translation 0.3 0.2 1.5 rotation 0 0.6 0.8 1.2 scale 0.4 0.5 0.3",
};

// Each placement a Shape of its own colour; `use` places one DEF'd geometry, else each Shape has a
// copy.
std::string placements_scene(const std::string& geometry, bool use) {
    std::string s =
        "Viewpoint { position 0 0 9 }\nDirectionalLight { direction -0.3 -0.5 -1 }\n"
        "PointLight { location 3 3 3 }\n";
    for (size_t i = 0; i < std::size(kPlacements); ++i) {
        const std::string g = !use ? geometry : i == 0 ? "DEF T " + geometry : "USE T";
        s += std::string("Transform { ") + kPlacements[i] +
             " children Shape { appearance Appearance { material Material { diffuseColor " +
             std::to_string(0.2 + 0.1 * double(i)) +
             " 0.5 0.7 specularColor 0.5 0.5 0.5 shininess 0.3 } } geometry " + g + " } }\n";
    }
    return s;
}

FlatScene flatten_text(const std::string& body, FlattenStats& stats) {
    LoadedScene loaded = load_scene_text("#VRML V2.0 utf8\n" + body, "instancing.wrl");
    EXPECT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    return flatten_scene(scene, FlattenOptions{}, diagnostics, stats);
}

Image render_scene(const FlatScene& scene) {
    RenderOptions o;
    o.width = 160;
    o.height = 120;
    o.threads = 2;
    Camera camera;
    std::string error;
    EXPECT_TRUE(make_camera(scene, o, camera, error)) << error;
    RenderStats stats;
    return render_image(scene, camera, o, nullptr, stats);
}

TEST(Instancing, FlattenStoresAUsedMeshOnce) {
    FlattenStats stats;
    const FlatScene used = flatten_text(placements_scene(torus(12, 6), true), stats);
    EXPECT_TRUE(used.meshes.empty());
    ASSERT_EQ(used.prototypes.size(), 1u);
    EXPECT_EQ(used.prototypes[0].triangle_count(), 144u);
    ASSERT_EQ(used.instances.size(), std::size(kPlacements));
    EXPECT_EQ(used.instanced_triangle_count(), 144u * std::size(kPlacements));
    EXPECT_EQ(stats.instances, std::size(kPlacements));
    EXPECT_EQ(stats.triangles, 144u * std::size(kPlacements));
    // Each placement keeps its own transform and colour.
    EXPECT_NEAR(used.instances[0].world_from_object[3][0], -2.2, 1e-15);
    EXPECT_NEAR(used.instances[3].world_from_object[0][0], -1.0, 1e-15);
    EXPECT_NE(used.instances[0].shading, used.instances[1].shading);

    // Copies stay world meshes, and so does a used mesh below 16 triangles.
    const FlatScene copies = flatten_text(placements_scene(torus(12, 6), false), stats);
    EXPECT_EQ(copies.meshes.size(), std::size(kPlacements));
    EXPECT_TRUE(copies.instances.empty());
    const FlatScene small =
        flatten_text(placements_scene(torus(4, 2), true), stats);  // 8 quads, 16 triangles
    EXPECT_EQ(small.instances.size(), std::size(kPlacements));
    const FlatScene tiny =
        flatten_text(placements_scene(torus(3, 2), true), stats);  // 12 triangles
    EXPECT_TRUE(tiny.instances.empty());
    EXPECT_EQ(tiny.meshes.size(), std::size(kPlacements));
}

// The image of instances is that of world-space copies: the same hit points (the barycentric point
// mapped to world space), normals (the corners' normals mapped and made unit, then interpolated, as
// the copies do), colours and texture coordinates. The tolerance is float output rounding: the two
// paths round positions differently in the last bits, which moves shading by ~1e-15.
TEST(Instancing, InstancesRenderAsTheirWorldCopies) {
    FlattenStats stats;
    const FlatScene used = flatten_text(placements_scene(torus(24, 12), true), stats);
    const FlatScene copies = flatten_text(placements_scene(torus(24, 12), false), stats);
    ASSERT_EQ(used.instances.size(), std::size(kPlacements));
    const Image a = render_scene(used), b = render_scene(copies);
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    double worst = 0.0;
    size_t lit = 0;
    for (size_t i = 0; i < a.rgba.size(); ++i) {
        worst = std::max(worst, double(std::fabs(a.rgba[i] - b.rgba[i])));
        lit += (i % 4 == 3 && a.rgba[i] > 0.0f) ? 1 : 0;
    }
    EXPECT_LE(worst, 1e-6);
    EXPECT_GT(lit, 1000u);  // the tori cover a good part of the image
}

// Closest hits through the instance's own BVH equal a test of every triangle, over instances mixed
// with spheres and world triangles; shadow queries agree.
TEST(Instancing, ClosestHitEqualsBruteForce) {
    FlattenStats stats;
    FlatScene scene = flatten_text(
        placements_scene(torus(24, 12), true) + "Shape { geometry " + torus(8, 4) +
            " }\n"
            "Transform { translation 0.5 0 0 children Shape { geometry Sphere { radius 0.6 } } }",
        stats);
    ASSERT_EQ(scene.instances.size(), std::size(kPlacements));
    ASSERT_EQ(scene.meshes.size(), 1u);
    Accel accel;
    accel.build(scene, 2);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    int hits = 0, instance_hits = 0;
    for (int i = 0; i < 20000; ++i) {
        Ray ray;
        ray.o = Vec3(u(rng), u(rng), 6.0 + u(rng));
        ray.d = Vec3(u(rng), u(rng), -6.0 + u(rng)) * 0.25 - ray.o * 0.1;
        Hit a, b;
        const bool ha = accel.intersect(ray, a), hb = accel.intersect_brute_force(ray, b);
        ASSERT_EQ(ha, hb) << i;
        EXPECT_EQ(accel.transmittance(ray), ha ? 0.0 : 1.0);
        if (!ha) continue;
        ++hits;
        EXPECT_EQ(a.t, b.t);
        EXPECT_EQ(a.prim, b.prim);
        if (prim_kind(a.prim) == PrimKind::Instance) {
            ++instance_hits;
            EXPECT_EQ(a.triangle, b.triangle);
            EXPECT_EQ(a.b1, b.b1);
        }
    }
    EXPECT_GT(instance_hits, 1000);
    EXPECT_GT(hits, instance_hits);
}

// A see-through instanced torus dims a shadow ray by its transparency once a crossing, as copies
// do.
TEST(Instancing, SeeThroughInstancesCountEveryCrossing) {
    FlattenStats stats;
    const std::string glass =
        "Shape { appearance Appearance { material Material { transparency 0.5 } } geometry ";
    const FlatScene scene =
        flatten_text("Transform { children " + glass + "DEF T " + torus(24, 12) +
                         " } }\nTransform { translation 0 0 -5 children " + glass + "USE T } }",
                     stats);
    ASSERT_EQ(scene.instances.size(), 2u);
    Accel accel;
    accel.build(scene, 1);
    Ray ray;                        // down through the tube of both tori: four crossings
    ray.o = Vec3(1.02, 0.05, 3.0);  // off the tessellation's edges, which two triangles share
    ray.d = Vec3(0.0, 0.0, -1.0);
    EXPECT_DOUBLE_EQ(accel.transmittance(ray), 0.0625);
    ray.t_max = 4.0;  // the first torus only
    EXPECT_DOUBLE_EQ(accel.transmittance(ray), 0.25);
}

// The corpus scenes that place textured meshes many times (the castle's towers and walls, the
// street lights): rendered with instances and with each instance replaced by its world-space copy,
// made as flatten makes the copies of meshes placed once (positions mapped, normals by the inverse
// transpose, corners swapped under a mirror), the images must be bit-identical: the same
// intersection and shading arithmetic, only organised in two BVH levels instead of one.
Mesh world_copy(const Mesh& prototype, const MeshInstance& in) {
    Mesh m = prototype;
    m.shading = in.shading;
    for (Vec3& p : m.positions) p = transform_point(in.world_from_object, p);
    const Mat3 linear(in.world_from_object);
    const Mat3 normal_from_object = glm::transpose(glm::inverse(linear));
    for (Vec3& n : m.normals) n = map_normal(normal_from_object, n);
    if (glm::determinant(linear) < 0.0)
        for (size_t c = 0; c + 2 < m.triangles.size(); c += 3) {
            std::swap(m.triangles[c + 1], m.triangles[c + 2]);
            if (!m.normals.empty()) std::swap(m.normals[c + 1], m.normals[c + 2]);
            if (!m.uvs.empty()) std::swap(m.uvs[c + 1], m.uvs[c + 2]);
            if (!m.colors.empty()) std::swap(m.colors[c + 1], m.colors[c + 2]);
        }
    return m;
}

// `textured`: the scene's textures must load (they lie in ../textures, next to the scene's folder).
void expect_instances_render_as_copies(const std::string& relative, bool textured) {
    const std::filesystem::path file = std::filesystem::path(VRMLRAY_CORPUS_DIR) / relative;
    if (!std::filesystem::exists(file))
        GTEST_SKIP() << "corpus file absent: " << file.parent_path().string();
    LoadOptions lo;
    lo.allowed_roots = {file.parent_path().parent_path()};
    LoadedScene loaded = load_scene(file, lo);
    ASSERT_TRUE(loaded.ok()) << loaded.diagnostics.format(loaded.sources);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.scene_file = loaded.main_file;
    fo.allowed_roots = loaded.allowed_roots;
    FlattenStats stats;
    FlatScene used = flatten_scene(scene, fo, diagnostics, stats);
    ASSERT_GT(used.instances.size(), 1u) << "the scene no longer instances: pick another";
    // Only the instanced meshes, framed by the camera (from the default viewpoint they may be small
    // or hidden): the lights, materials and textures stay the scene's.
    used.meshes.clear();
    used.spheres.clear();
    used.quadrics.clear();
    if (textured) {
        ASSERT_GT(used.textures.size(), 0u) << "the scene's textures were not found";
        size_t textured_instances = 0;
        for (const MeshInstance& in : used.instances)
            textured_instances +=
                used.materials[used.shadings[in.shading].material].texture >= 0 ? 1 : 0;
        ASSERT_GT(textured_instances, 0u);
    }
    // One instance at a time, framed by the camera, against its copy.
    RenderOptions o;
    o.width = 120;
    o.height = 80;
    o.threads = 2;
    o.fit = true;
    size_t differ = 0, covered = 0;
    for (const MeshInstance& in : std::vector<MeshInstance>(used.instances)) {
        FlatScene one = used;
        one.instances = {in};
        FlatScene copy = used;
        copy.instances.clear();
        copy.prototypes.clear();
        copy.meshes = {world_copy(used.prototypes[in.prototype], in)};
        Camera camera;
        std::string error;
        ASSERT_TRUE(make_camera(one, o, camera, error)) << error;
        RenderStats rs;
        const Image a = render_image(one, camera, o, nullptr, rs);
        const Image b = render_image(copy, camera, o, nullptr, rs);
        ASSERT_EQ(a.rgba.size(), b.rgba.size());
        for (size_t i = 0; i < a.rgba.size(); i += 4) {
            differ += std::memcmp(&a.rgba[i], &b.rgba[i], 4 * sizeof(float)) != 0 ? 1 : 0;
            covered += a.rgba[i + 3] > 0.0f ? 1 : 0;
        }
    }
    const size_t pixels = used.instances.size() * size_t(o.width * o.height);
    EXPECT_EQ(differ, 0u) << "pixels that differ, of " << pixels;
    // Lamp posts are thin and walls flat (framed, they cover 1.4% and 5% of their images): at least
    // 1000 pixels are compared.
    EXPECT_GT(covered, 1000u) << "the instances cover too little of their images";
}

TEST(Instancing, CorpusCastleInstancesRenderAsCopies) {
    expect_instances_render_as_copies(
        "vrml97/castle-engine-demo-models/castle/old/vrml_2/castle.wrl", true);
}

TEST(Instancing, CorpusStreetLightsInstancesRenderAsCopies) {
    // No textures in this one: eight lights with radii over instanced lamp posts.
    expect_instances_render_as_copies(
        "x3d/castle-engine-demo-models/lights_materials/light_street_lights_radius.x3d", false);
}

}  // namespace
}  // namespace vr
