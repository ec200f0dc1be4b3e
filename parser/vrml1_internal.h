// The two stages of reading VRML 1.0: the file as written (nodes, fields and children, DEF/USE as
// shared node indices), then the upgrade that walks it with the VRML 1.0 traversal state and emits
// VRML97 nodes. Field values of both stages live in the scene tree's pools, so the upgrade reuses
// large arrays (points, indices, colours) instead of copying them.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "parser/load.h"
#include "parser/node_tree.h"
#include "parser/registry.h"

namespace vr::vrml1 {

constexpr uint32_t kNone = UINT32_MAX;

// One node as written in a VRML 1.0 file.
struct V1Node {
    const NodeTypeDecl* decl = nullptr;  // its VRML 1.0 interface
    Name type = kNoName;
    Name def_name = kNoName;
    SourceLoc loc;             // where the type name stands
    uint32_t first_field = 0;  // into V1File::fields
    uint32_t field_count = 0;
    uint32_t first_child = 0;  // into V1File::children
    uint32_t child_count = 0;
    NodeId vrml97 =
        kNullNode;        // a VRML97 node written in the file (a browser extension), read as is
    bool shared = false;  // named by a USE (the upgrade extends this to its descendants)
};

struct V1File {
    uint32_t file = 0;  // source file index
    std::vector<V1Node> nodes;
    std::vector<FieldEntry> fields;
    std::vector<uint32_t> children;
    std::vector<uint32_t> roots;
};

// Reads the text of source `file`; false after a syntax error (reported in scene.diagnostics).
bool read_file(LoadedScene& scene, uint32_t file, const LoadLimits& limits, V1File& out);

// Walks the file's nodes with VRML 1.0 semantics and adds VRML97 nodes to scene.tree; returns the
// roots. False when a limit stopped it (reported in scene.diagnostics).
bool upgrade(LoadedScene& scene, const V1File& file, const LoadLimits& limits,
             std::vector<NodeId>& roots);

// SFEnum and SFBitMask fields are SFString fields whose range text lists the allowed words
// ("A|B|C").
bool is_enum_field(const FieldDecl& field);

// The VRML97 node a VRML 1.0 node becomes (for the extension-field table), or an empty view.
std::string_view vrml97_counterpart(std::string_view vrml1_type);

}  // namespace vr::vrml1
