// The reader of the classic encodings (VRML97 `#VRML V2.0 utf8`, X3D classic `#X3D V3.x utf8`).
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "parser/load.h"
#include "parser/proto.h"
#include "parser/units.h"

namespace vr {

// Resolves an EXTERNPROTO: its URLs, the file that declares it and its name. Returns null (after
// adding a warning) when no URL leads to a usable PROTO.
using ExternProtoResolver = std::function<std::shared_ptr<const ProtoDecl>(
    const std::vector<std::string>& urls, uint32_t from_file, SourceLoc where, Name name)>;

struct ClassicResult {
    std::vector<NodeId> roots;
    std::shared_ptr<ProtoScope> protos;   // the file's top-level PROTOs (for EXTERNPROTO lookups)
    bool ok = true;                       // false: a syntax error stopped the reader
    FileUnits units;                      // the file's UNIT statements
    std::string x3d_version;              // XML: the <X3D version> attribute (classic: the header)
    std::vector<ConsumedPiece> consumed;  // pieces the PieceConsumer took, places in `roots`
};

// Reads the text of source file `file` (already in scene.sources) into scene.tree. With a
// `consumer`, pieces it takes are not added to the tree (ClassicResult::consumed).
ClassicResult read_classic(LoadedScene& scene, uint32_t file, Spec spec, const LoadLimits& limits,
                           const ExternProtoResolver& resolve_externproto,
                           PieceConsumer* consumer = nullptr);

}  // namespace vr
