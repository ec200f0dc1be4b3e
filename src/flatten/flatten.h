// Typed scene -> the tracer's FlatScene: world-space primitives, deduplicated materials and
// shadings, light sets, textures, viewpoints, background, fog, headlight.
//
// What it does and how it reads the specifications:
// * Transforms compose down the graph; a node USEd n times is emitted n times (each with its own
//   world transform). Meshes are triangulated once per geometry node; a mesh of 16 triangles or
//   more placed a second time becomes a prototype in object space, and every placement an instance
//   (MeshInstance), so its triangles are stored once; smaller ones are copied to world space per
//   use. A subtree under a singular Transform is skipped (build_scene warned).
// * Sphere: under a rotation and uniform scale it stays a Sphere (world centre and radius); under
//   any other scale it becomes an Ellipsoid quadric. Its `gas` flag: the sphereMode hint (Sphere
//   over Shape over Material) if set, else --spheres (FromHints and Opaque give opaque).
// * Box/Cylinder/Cone: quadrics in object space with world_from_object the shape's transform.
// * Materials: Material as VRML97; PhysicalMaterial as a Material with diffuse = baseColor,
//   emissive, transparency and the reflectivity hint metallic*(1-roughness) unless a reflectivity
//   hint is given; UnlitMaterial as a Material that only emits its emissiveColor (diffuse, specular
//   and ambient 0), or unlit (lit FALSE, texture colour) when textured; no Material: unlit. Hints
//   override. Gas parameters are resolved here: density = hint or FlattenOptions::density, albedo =
//   hint or diffuseColor, emission = hint or emissiveColor. Identical materials (every field equal)
//   share one entry.
// * Lights: DirectionalLight lights the subtree of its parent group (X3D `global` TRUE:
//   everything); PointLight/SpotLight light everything (X3D `global` FALSE: their parent's
//   subtree). `on FALSE` lights are dropped. Positions and directions go to world space; radius is
//   scaled by |det|^(1/3) of the transform's linear part (exact for uniform scales; the geometric
//   mean of the axis scales otherwise). Each shape's light set = the scoped lights above it + all
//   global lights.
// * Bindable nodes: the first NavigationInfo, Background and Fog in file order are used, preferring
//   the main file's over inlined files' (VRML97 4.6.10 binds none from Inlines; we fall back to
//   them when the main file has none). Viewpoints keep file order with the main file's first (their
//   fieldOfView, and Background's colours and angles, were checked by build_scene); OrthoViewpoint
//   extents are scaled like a light's radius. Background rotation: the rotation of its transform
//   (scale removed). Fog visibilityRange is scaled like a light's radius. Bindable nodes under a
//   Billboard ignore the Billboard's rotation.
// * Billboard: rotates its children about axisOfRotation so that local +Z points at the chosen
//   viewpoint (options.viewpoint, else the first; with none the default camera at 0 0 10). Axis 0 0
//   0 is screen-aligned: local +Z along the camera's backward axis and +Y along its up axis. (--fit
//   moves the camera after flattening; billboards keep facing the viewpoint.)
// * Textures: URLs resolved with resolve_url from the file the node stands in, limited to
//   FlattenOptions::allowed_roots (or Scene::allowed_roots when empty; both empty: anywhere, as
//   without --sandbox); loaded once per file and
//   way of sampling it (core/texture_sampling.h). A texture that cannot be found or read, or has
//   more than max_texture_pixels texels, is one warning; the shape renders untextured.
#pragma once
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "image/texture_file.h"
#include "parser/diagnostics.h"
#include "render/flat_scene.h"
#include "render/options.h"
#include "scene/scene.h"

namespace vr {

struct FlattenOptions {
    SpheresOption spheres = SpheresOption::FromHints;
    double density = 1.0;
    // Render a triangle mesh (IndexedFaceSet, IndexedTriangleSet, TriangleSet, ...) whose
    // vertices all lie on one sphere or cylinder along an axis of the mesh, to the precision they
    // were written with, as that exact shape (Jmol's, ChimeraX's atoms and bonds); unset: on
    // in gas mode, off otherwise. A sphere under a non-uniform scale becomes an ellipsoid quadric,
    // except in gas mode (gas needs true spheres: the mesh stays).
    std::optional<bool> recover_spheres;
    std::optional<Vec3> albedo;  // --albedo: gas albedo where no hint says (default: diffuseColor)
    std::optional<Vec3>
        emission;           // --emission: gas emission where no hint says (default: emissiveColor)
    std::string viewpoint;  // for Billboard: faces the chosen viewpoint (first if empty)
    std::filesystem::path scene_file;
    std::vector<std::filesystem::path> allowed_roots;
    // Bounds against instancing blow-up (a DEF'd group USEd many times inside other USEd groups):
    // past them flattening stops emitting with one error. 50M spheres already take 2 GB in the
    // FlatScene.
    size_t max_primitives = 50'000'000;  // spheres + quadrics + meshes
    size_t max_triangles = 100'000'000;
    size_t max_group_visits = 100'000'000;
    size_t max_depth =
        2000;  // group nesting along one path (deeper parts are skipped with a warning)
    // An ImageTexture with more texels (width x height, read from the file's header before
    // decoding) is refused with the usual unreadable-texture warning, naming the size.
    size_t max_texture_pixels = kDefaultMaxTexturePixels;
    // The image's size in pixels, for X3D Layout's FRACTION and PIXEL units and the layers'
    // Viewports (docs/rendering.md "Layers"); 0: unknown (a pixel is then a unit).
    int image_width = 0, image_height = 0;
};

// Why a mesh tried for recovery (FlattenOptions::recover_spheres) stayed a mesh. The first five are
// FitFailure's (geometry/sphere_fit.h), in its order.
enum class RecoveryMiss : uint8_t {
    OffSurface,
    TooFewPoints,
    CoarselyWritten,
    NotAllAround,
    PartialCap,
    Textured,       // has a texture: the exact shape would map it differently
    Colored,        // per-vertex colours, which the exact shape cannot carry
    NonUniformGas,  // a sphere under a non-uniform scale, in gas mode
    kCount
};
const char* recovery_miss_label(RecoveryMiss m);

struct FlattenStats {
    size_t spheres = 0, quadrics = 0, meshes = 0, triangles = 0, materials = 0, lights = 0,
           textures = 0;
    size_t instances =
        0;  // placements of instanced meshes (not in `meshes`; their triangles are in `triangles`)
    size_t skipped_shapes = 0;  // shapes with no renderable geometry
    // Recovery (FlattenOptions::recover_spheres), counted per placement: triangle meshes tried,
    // those rendered as exact spheres, ellipsoids and cylinders, and why the others were not.
    size_t recovery_candidates = 0;
    size_t recovered_spheres = 0, recovered_ellipsoids = 0, recovered_cylinders = 0;
    std::array<size_t, size_t(RecoveryMiss::kCount)> recovery_misses{};
};

FlatScene flatten_scene(const Scene& scene, const FlattenOptions& options, Diagnostics& diagnostics,
                        FlattenStats& stats);
// The same flat scene, freeing the typed scene's per-node arrays as the walk leaves them behind
// where the scene's shape allows (a molecule export: a subtree per atom, none shared), so that
// the typed nodes and the flat primitives are not all held at once. `scene` is then fit only to
// be destroyed.
FlatScene flatten_scene_releasing(Scene& scene, const FlattenOptions& options,
                                  Diagnostics& diagnostics, FlattenStats& stats);

}  // namespace vr
