// What the tracer sees: world-space primitives in plain arrays, materials, lights, cameras,
// background. Built by the flattening step (src/flatten/) from the typed scene; knows
// nothing of VRML nodes.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/texture_sampling.h"

namespace vr {

enum class SphereMode : uint8_t { Opaque, Gas };

struct Texture {
    int width = 0;
    int height = 0;
    int channels = 0;  // 1 intensity, 2 intensity+alpha, 3 RGB, 4 RGBA (VRML's texture types)
    std::vector<float> texels;  // channels floats a texel, row 0 = BOTTOM of the image (VRML t = 0)
    TextureSampling sampling;   // wrap modes and filter (TextureProperties)
};

// A resolved Appearance: VRML Material fields plus our hints.
struct Material {
    bool lit = true;  // false when the Appearance has no Material: unlit, colour = texture or white
    Vec3 diffuse{0.8};
    Vec3 specular{0.0};
    Vec3 emissive{0.0};
    double ambient_intensity = 0.2;
    double shininess = 0.2;
    double transparency = 0.0;
    double reflectivity = 0.0;    // hint
    double ior = 1.0;             // hint
    int32_t texture = -1;         // index into FlatScene::textures
    Mat3 texture_transform{1.0};  // applied to (s, t, 1)
    // X3D 4: an RGB texture multiplies the colour; VRML97 and X3D 3: it replaces it.
    bool texture_modulates = false;
    // Gas hints (docs/rendering.md, Gas mode); negative/unset values mean "use the global option or
    // the default".
    int8_t sphere_mode = -1;  // -1 unset, else SphereMode
    double density = -1.0;
    Vec3 albedo{-1.0};
    Vec3 emission{-1.0};
};

// Which material and which lights shade a primitive (DirectionalLight is scoped to its group).
struct Shading {
    uint32_t material = 0;
    uint32_t light_set = 0;  // index into FlatScene::light_sets
    // X3D solid geometry: camera and secondary rays pass through its back faces (Accel::intersect);
    // shadow rays do not (docs/rendering.md, Back faces).
    bool cull_back_faces = false;
    uint32_t scope = 0;  // index into FlatScene::scopes; 0: no ClipPlane, no LocalFog
};

struct Sphere {
    Vec3 center;
    double radius = 1.0;
    uint32_t shading = 0;
    bool gas = false;  // resolved from hints and --spheres by flatten
};

// Box, Cylinder, Cone, or a sphere under a non-uniform scale (ellipsoid), kept analytic in object
// space.
enum class QuadricKind : uint8_t { Box, Cylinder, Cone, Ellipsoid };
struct Quadric {
    QuadricKind kind = QuadricKind::Box;
    Mat4 world_from_object{1.0};
    Mat4 object_from_world{1.0};
    Vec3 size{
        2.0};  // Box: full size; Cylinder/Cone: (2*radius, height, 2*radius); Ellipsoid: 2*radius
    bool side = true, top = true, bottom = true;  // Cylinder/Cone parts
    uint32_t shading = 0;
};

// Triangles with per-corner attributes; corner k of triangle t has index 3*t + k.
struct Mesh {
    std::vector<Vec3> positions;      // world space
    std::vector<uint32_t> triangles;  // 3 position indices a triangle
    std::vector<Vec3> normals;   // per corner, world space, unit; empty: flat (geometric) normals
    std::vector<Vec2> uvs;       // per corner; empty: no texture coordinates
    std::vector<Vec3> colors;    // per corner (Color node); empty: material colour
    std::vector<double> alphas;  // per corner with `colors` (ColorRGBA); empty: RGB colours
    // Per corner (FogCoordinate): the fog amount in [0, 1] that replaces the distance's; empty:
    // none.
    std::vector<double> fog_depths;
    bool solid = true;  // false: both sides are lit (two-sided)
    uint32_t shading = 0;
    size_t triangle_count() const { return triangles.size() / 3; }
};

// A mesh that the file places more than once (DEF/USE): its triangles are stored once, in object
// space (FlatScene::prototypes, whose own `shading` is unused), and each placement is an instance
// with its own transform and shading. The tracer gives each prototype a BVH of its own and each
// instance one entry in the scene's BVH.
struct MeshInstance {
    uint32_t prototype = 0;
    Mat4 world_from_object{1.0};
    Mat4 object_from_world{1.0};
    uint32_t shading = 0;
};

enum class LightKind : uint8_t { Directional, Point, Spot };
struct Light {
    LightKind kind = LightKind::Directional;
    Vec3 color{1.0};
    double intensity = 1.0;
    double ambient_intensity = 0.0;
    Vec3 position{0.0};              // world (point, spot)
    Vec3 direction{0.0, 0.0, -1.0};  // world, unit: the direction light travels (directional, spot)
    Vec3 attenuation{1.0, 0.0, 0.0};
    double radius = 100.0;  // world units (point, spot)
    double beam_width = 1.570796;
    double cutoff_angle = 0.785398;
    bool headlight = false;       // follows the camera: direction set per render, never shadowed
    double source_radius = 0.0;   // point, spot: a uniformly bright sphere (docs/rendering.md, Soft
                                  // light with error bounds); 0: a point
    double angular_radius = 0.0;  // directional: a disc of this angular radius; 0: a direction
};

struct Viewpoint {
    std::string def_name;
    std::string description;
    bool ortho = false;
    Vec3 position{0.0, 0.0, 10.0};  // world
    Mat3 world_from_camera{
        1.0};  // columns: camera right (+x), up (+y), backward (+z); looks along -z
    double field_of_view = 0.785398;  // perspective: angle spanning the smaller image dimension
    // OrthoViewpoint: extents (min x, min y, max x, max y) in camera units; the smaller dimension
    // is fit.
    double ortho_extent[4] = {-1.0, -1.0, 1.0, 1.0};
};

struct Background {
    std::vector<Vec3> sky_colors{Vec3(0.0)};
    std::vector<double> sky_angles;
    std::vector<Vec3> ground_colors;
    std::vector<double> ground_angles;
    int32_t panorama[6] = {-1, -1, -1, -1, -1, -1};  // front back left right top bottom -> textures
    Mat3 world_from_background{1.0};  // Background is rotated by its parent transforms
    bool present = false;             // a Background node was bound
};

enum class FogKind : uint8_t { None, Linear, Exponential };
struct Fog {
    FogKind kind = FogKind::None;
    Vec3 color{1.0};
    double visibility_range = 0.0;  // world units; 0 disables fog
};

struct Bounds3 {
    Vec3 lo{kInf};
    Vec3 hi{-kInf};
    bool empty() const { return lo.x > hi.x; }
    void extend(const Vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void extend(const Bounds3& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
};

// Lines and points (IndexedLineSet, LineSet, PointSet): world-space marks of a fixed size on the
// screen (--line-width, --point-size pixels), unlit, seen by camera rays only (render/lines.h).
struct LineSegment {
    Vec3 a, b;                            // world
    Vec3 color_a, color_b;                // at a and at b
    double alpha_a = 1.0, alpha_b = 1.0;  // opacity at a and b: the mark over what is behind it
};
struct PointMark {
    Vec3 position;  // world
    Vec3 color;
    double alpha = 1.0;
};

// ---- X3D ClipPlane, LocalFog, Layering (docs/rendering.md "Layers", "ClipPlane")

// What the ClipPlane and LocalFog nodes of the groups above a shape do to it.
struct ShadingScope {
    // World space: a point p of the shape exists (is seen, casts shadows) when dot(xyz, p) + w >= 0
    // for every plane; xyz is unit.
    std::vector<Vec4> clip_planes;
    int32_t local_fog = -1;  // into FlatScene::local_fogs; -1: the scene's fog
};

struct FlatScene;
// One layer of an X3D LayerSet, drawn over the layers before it in FlatScene::layers.
struct FlatLayer {
    std::shared_ptr<const FlatScene>
        scene;                              // null: the FlatScene holding the list (the active one)
    double clip[4] = {0.0, 1.0, 0.0, 1.0};  // Viewport: left right bottom top, image fractions
    bool full() const {
        return clip[0] <= 0.0 && clip[1] >= 1.0 && clip[2] <= 0.0 && clip[3] >= 1.0;
    }
};

struct FlatScene {
    std::vector<LineSegment> segments;
    std::vector<PointMark> points;
    std::vector<Sphere> spheres;
    std::vector<Quadric> quadrics;
    std::vector<Mesh> meshes;      // world space
    std::vector<Mesh> prototypes;  // object space, placed by instances
    std::vector<MeshInstance> instances;
    std::vector<Material> materials;
    std::vector<Shading> shadings;
    std::vector<Texture> textures;
    std::vector<Light> lights;                      // scene lights (no headlight)
    std::vector<std::vector<uint32_t>> light_sets;  // indices into lights
    bool headlight = true;                          // NavigationInfo headlight
    std::vector<Viewpoint> viewpoints;              // in file order
    Background background;
    Fog fog;
    // scopes[0] is empty (no clipping, the scene's fog); more only with ClipPlane or LocalFog.
    std::vector<ShadingScope> scopes{ShadingScope{}};
    std::vector<Fog> local_fogs;
    // X3D layers in drawing order, the first with its background, each later one over them with
    // its own camera and depth; empty: this scene alone (no LayerSet, or one full-image layer).
    std::vector<FlatLayer> layers;
    bool any_clip_planes() const {
        for (const ShadingScope& s : scopes)
            if (!s.clip_planes.empty()) return true;
        return false;
    }
    // Of all renderable primitives, those of the layers seen through this scene's camera (the ones
    // without a Viewpoint) included; the spheres' part on `threads` threads (0: all cores).
    Bounds3 bounds(int threads = 1) const;
    size_t triangle_count() const;            // in meshes (each stored once)
    size_t instanced_triangle_count() const;  // placed by instances, counted once a placement
};

}  // namespace vr
