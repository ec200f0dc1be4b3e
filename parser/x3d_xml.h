// The X3D XML encoding (.x3d), read with libxml2 into the same node tree as the classic reader.
#pragma once
#include "parser/classic.h"
#include "parser/load.h"

namespace vr {

// Reads the XML text of source file `file` into scene.tree. External entities and DTDs are never loaded.
ClassicResult read_x3d_xml(LoadedScene& scene, uint32_t file, const LoadLimits& limits);

}  // namespace vr
