// Renderer hints (docs/input.md, Renderer hints): a MetadataSet named "vrmlray" in the `metadata`
// field of a Material, Shape or Sphere, holding
// MetadataString/MetadataFloat/MetadataDouble/MetadataInteger values named sphereMode ("opaque" |
// "gas"), density (>= 0), reflectivity (0..1), ior (> 0), albedo and emission (RGB, each >= 0; a
// single number means grey). A "vrmlray" set nested inside another MetadataSet is found too.
// Unknown names and bad values are warnings; the hint is then not set.
#pragma once
#include "parser/diagnostics.h"
#include "parser/node_tree.h"
#include "scene/scene.h"

namespace vr {

// Reads the hints from `metadata` (the value of a node's metadata field; kNullNode gives no hints).
sg::Hints read_hints(const NodeTree& tree, NodeId metadata, Diagnostics& diagnostics);

}  // namespace vr
