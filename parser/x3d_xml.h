// The X3D XML encoding (.x3d), read with libxml2 into the same node tree as the classic reader.
#pragma once
#include <string_view>

#include "parser/classic.h"
#include "parser/load.h"

namespace vr {

// Reads the XML text of source file `file` into scene.tree. External entities and DTDs are never
// loaded.
ClassicResult read_x3d_xml(LoadedScene& scene, uint32_t file, const LoadLimits& limits);
// The same, resolving ExternProtoDeclare URLs with `resolve_externproto` (the loader's resolver).
// A large file is read in pieces on all cores, as the classic reader reads one (classic_pieces.h);
// with a `consumer`, pieces it takes are not added to the tree (ClassicResult::consumed).
ClassicResult read_x3d_xml(LoadedScene& scene, uint32_t file, const LoadLimits& limits,
                           const ExternProtoResolver& resolve_externproto,
                           PieceConsumer* consumer = nullptr);

// The field of its parent a node element goes into when it has no containerField attribute:
// "geometry" for geometry nodes, "material" for materials, ..., "children" for everything else.
std::string_view x3d_default_container_field(std::string_view node_type);

// The X3D name of a field that VRML97 named differently (Switch choice -> children, LOD level ->
// children, Collision collide -> enabled); any other field name is returned unchanged.
std::string_view x3d_field_name(std::string_view node_type, std::string_view field);

}  // namespace vr
