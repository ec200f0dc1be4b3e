// `vrmlray convert --recover-spheres`: a node tree rewritten into the compact exact scene a
// molecular export stands for (docs/manual.md "convert"). Tessellated atoms and bonds
// (IndexedFaceSet, IndexedTriangleSet, TriangleSet meshes that the recognisers of
// geometry/sphere_fit.h and geometry/cylinder_fit.h take for exact shapes) become Sphere and
// Cylinder nodes, and identical Materials, Appearances, Shapes and primitive geometry are one node
// written once (DEF) and referred to (USE).
#pragma once
#include <array>
#include <cstddef>

#include "flatten/flatten.h"
#include "parser/node_tree.h"

namespace vr {

struct CompactStats {
    // Mesh nodes (not placements) tried, those replaced by a Sphere or a Cylinder, and why the
    // others stayed meshes (the renderer's reasons: flatten/flatten.h).
    size_t meshes = 0, spheres = 0, cylinders = 0;
    std::array<size_t, size_t(RecoveryMiss::kCount)> misses{};
    // Nodes replaced by an identical one (same type, same field values, same children).
    size_t shared = 0;
};

// Replaces every exact sphere or cylinder mesh of the tree by the Sphere or Cylinder node it
// stands for. A mesh centred on its origin (a sphere) or along its y axis (a cylinder) is
// replaced where it stands; any other is placed by a new Transform around a new Shape, which
// stands where each Shape holding the mesh stood. Meshes that a ROUTE, a PROTO interface or an
// EXPORT names, textured ones and ones with per-vertex colours are kept.
void recover_exact_nodes(NodeTree& tree, CompactStats& stats);

// Makes identical Material, TwoSidedMaterial, Appearance, Sphere, Cylinder, Cone, Box and Shape
// nodes one node, which the writers then write once and USE. Nodes that a ROUTE, a PROTO interface
// or an EXPORT names are kept apart (their events are their own).
void share_identical_nodes(NodeTree& tree, CompactStats& stats);

}  // namespace vr
