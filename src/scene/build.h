// Node tree -> typed scene graph (scene.h). Reads every node docs/input.md says the tracer models,
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
#include <optional>
#include <span>

#include "parser/diagnostics.h"
#include "parser/load.h"
#include "scene/scene.h"

namespace vr {

// Where the scene build finds the fragments of LoadedScene::consumed_pieces (built from pieces of a
// large file while it was read): LoadedScene::piece_consumer is one (src/scene/fragments.h). The
// build splices each in at its place among the top-level nodes, so that the scene equals the one
// built from the whole tree.
class FragmentStore {
  public:
    virtual ~FragmentStore() = default;
    virtual Scene* fragment(size_t piece) = 0;  // null: none was built
    virtual void release(size_t piece) = 0;     // spliced in: its memory may go
};

// The scene of one piece of a file: `roots` of `tree` as the top-level nodes of a file of their
// own. Outer nodes (parser/piece_consumer.h) may stand as a Shape's appearance; the splice resolves
// them. `diagnostics` gets the build's messages; nullopt when the builder misread a field (a bug
// the unit tests catch).
std::optional<Scene> build_fragment(const NodeTree& tree, std::span<const NodeId> roots,
                                    Diagnostics& diagnostics);

Scene build_scene(const LoadedScene& loaded, Diagnostics& diagnostics);
// The same scene, for a caller that needs the node tree no more: when the tree allows it (no DEF
// shared by USE, no PROTO, ROUTE or Inline), the memory of the top-level nodes already built is
// given back while the later ones are, so that the tree and the scene are not both held whole.
// `loaded.tree` is empty afterwards.
Scene build_scene_releasing_tree(LoadedScene& loaded, Diagnostics& diagnostics);

}  // namespace vr
