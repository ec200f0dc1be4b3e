// Writing a node tree as X3D XML (.x3d). PROTO instances are written expanded; DEF/USE sharing and
// DEF names are kept as the classic writer keeps them; fields VRML97 named differently get their
// X3D names.
#pragma once
#include <string>

#include "parser/node_tree.h"

namespace vr {

// A well-formed, indented X3D document: version 3.3, or 4.0 when a node or field only X3D 4.0 has
// is used. compact (`convert --recover-spheres`): no indentation, no zero before a decimal point.
// Atoms stay Transforms: a ProtoInstance (`<ProtoInstance name='A'><fieldValue name='t'
// value='...'/></ProtoInstance>`) takes as many bytes as a Transform whose Shape is a USE.
std::string write_x3d_xml(const NodeTree& tree, bool compact = false);

// Whether the tree uses a node type or field that X3D 3.3 does not have (e.g. PhysicalMaterial).
bool needs_x3d_4(const NodeTree& tree);

}  // namespace vr
