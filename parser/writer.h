// Writing a node tree back out in a classic encoding (VRML97 or X3D classic). PROTO instances are
// written expanded; DEF/USE sharing is kept, and DEF names are kept (made unique where expansion
// repeated one).
#pragma once
#include <string>

#include "parser/load.h"
#include "parser/node_tree.h"

namespace vr {

// target: Encoding::Vrml97 or Encoding::X3dClassic.
std::string write_classic(const NodeTree& tree, Encoding target);

// Formats one number the shortest way that reads back to the same double.
std::string format_number(double value);

}  // namespace vr
