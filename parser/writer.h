// Writing a node tree back out in a classic encoding (VRML97 or X3D classic). PROTO instances are
// written expanded; DEF/USE sharing is kept, and DEF names are kept (made unique where expansion
// repeated one).
#pragma once
#include <string>

#include "parser/load.h"
#include "parser/node_tree.h"

namespace vr {

// target: Encoding::Vrml97 or Encoding::X3dClassic. compact: each node's fields on one line and
// no indentation (a child list still puts each child on a line of its own; a list of one child
// is written without brackets), for `convert --recover-spheres`, whose output is meant small.
std::string write_classic(const NodeTree& tree, Encoding target, bool compact = false);

// Formats one number the shortest way that reads back to the same double.
std::string format_number(double value);
// format_number without the zero before the point (".5", "-.5"): what compact output writes.
std::string format_number_compact(double value);

// Whether a node read with a VRML97 interface must say `solid FALSE` when written as X3D (classic
// or XML): X3D's interface of its type has `solid` and the node's value (its own, or X3D's default
// for VRML97's Sphere, Box, Cone and Cylinder, which have none) is TRUE. VRML97's `solid TRUE`
// lets a browser cull back faces, X3D's requires it (docs/rendering.md "Back faces"), and vrmlray
// draws a VRML97 node's both faces: written as X3D with `solid TRUE` the same surface would lose
// its back faces (PyMOL's barnase_figure.wrl, whose ligand mesh is wound either way).
bool needs_solid_false_in_x3d(const NodeTree& tree, NodeId id);

}  // namespace vr
