// Structural equality of two node trees, for tests of the readers and writers: the same node types,
// field values (set fields, each compared with the other tree's value or default), DEF names and
// DEF/USE sharing.
#pragma once
#include <string>

#include "parser/node_tree.h"

namespace vr {

struct TreeCompareOptions {
    // `b` was written from `a` and read back: expect the DEF names a writer gives (unique names,
    // made-up names for shared nodes that had none) instead of `a`'s own, and `solid FALSE` on a
    // VRML97 node written as X3D (parser/writer.h, needs_solid_false_in_x3d).
    bool names_as_written = false;
    // Numbers may differ by this much relative to their magnitude (0: exactly equal).
    double relative_tolerance = 0.0;
};

// "" when the trees are equal; else where and how they first differ, e.g.
// "roots[0] Transform.children[1] Shape.geometry Box: field 'size': 1 2 3 vs 1 2 4".
std::string compare_trees(const NodeTree& a, const NodeTree& b,
                          const TreeCompareOptions& options = {});

}  // namespace vr
