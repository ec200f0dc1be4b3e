// Browser.createVrmlFromString / createX3DFromString (docs/scripts.md): scene text read as a file
// of its own and its nodes appended to the world's node tree.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "parser/node_tree.h"

namespace vr {

// Reads `text` (VRML97 or X3D classic, or X3D XML when it starts with '<'; `x3d` picks the
// classic header) as a file at `anchor` (relative URLs resolve from there, confined to
// `allowed_roots` when not empty) and appends its nodes to `tree`, every place in them set to
// `at`. Returns the new top-level nodes; empty with `error` set when the text has an error.
std::vector<NodeId> read_nodes_into(NodeTree& tree, const std::string& text, bool x3d,
                                    const std::filesystem::path& anchor,
                                    const std::vector<std::filesystem::path>& allowed_roots,
                                    PackedLoc at, std::string& error);

// Appends every node of `from` to `tree` (kinds, fields and pools remapped; places set to `at`).
// Returns the id `from`'s node 0 has in `tree`.
NodeId append_tree(NodeTree& tree, const NodeTree& from, PackedLoc at);

}  // namespace vr
