// Node tree -> typed scene graph (scene.h). Reads every node SPEC section 2 says the tracer models,
// from VRML97 and X3D alike (e.g. Switch `choice` or `children`, LOD `level` or `children`, X3D
// `global` on lights, PhysicalMaterial, UnlitMaterial, CoordinateDouble, ColorRGBA), with values
// from the file or the grammar's defaults.
//
// Messages name the node (type and DEF name) at its place in the file; each cause is one warning,
// counted:
// * a node reached again inside itself (a DEF/USE cycle): warning, the inner use is skipped;
// * nesting deeper than kMaxDepth through USE chains: warning, the deeper part is skipped;
// * a node of the wrong kind in a field (e.g. a Material as geometry): warning, treated as absent;
// * PointSet, IndexedLineSet, LineSet, Text and the 2D lines have no area: one warning a type,
//   skipped;
// * node types that draw nothing (sensors, interpolators, Script, WorldInfo, ...) are skipped
//   silently; others that vrmlray does not model get one warning a type;
// * a singular or non-finite Transform: warning, its subtree is marked and skipped by flattening.
#pragma once
#include "parser/diagnostics.h"
#include "parser/load.h"
#include "scene/scene.h"

namespace vr {

Scene build_scene(const LoadedScene& loaded, Diagnostics& diagnostics);
// The same scene, for a caller that needs the node tree no more: when the tree allows it (no DEF
// shared by USE, no PROTO, ROUTE or Inline), the memory of the top-level nodes already built is
// given back while the later ones are, so that the tree and the scene are not both held whole.
// `loaded.tree` is empty afterwards.
Scene build_scene_releasing_tree(LoadedScene& loaded, Diagnostics& diagnostics);

}  // namespace vr
