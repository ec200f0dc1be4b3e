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

}  // namespace vr
