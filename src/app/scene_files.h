// The file names a scene may have: the one list that the command line's help, its guess that a word
// names a scene, a batch's output names and convert's choice of encoding read.
#pragma once
#include <string>
#include <string_view>

#include "parser/load.h"

namespace vr {

struct SceneExtension {
    const char* name;  // lower case, with its dot
    Encoding encoding;
    bool gzip;  // the name says the file is gzip-compressed
};

// Any of them may also end in ".gz". In the order convert's messages list them: each plain
// encoding, then its gzip name.
inline constexpr SceneExtension kSceneExtensions[] = {
    {".wrl", Encoding::Vrml97, false},      {".x3dv", Encoding::X3dClassic, false},
    {".x3d", Encoding::X3dXml, false},      {".wrz", Encoding::Vrml97, true},
    {".x3dvz", Encoding::X3dClassic, true}, {".x3dz", Encoding::X3dXml, true}};

// The entry `lower_name` (lower case, ".gz" already taken off) ends in, or nullptr.
inline const SceneExtension* scene_extension_of(std::string_view lower_name) {
    for (const SceneExtension& e : kSceneExtensions)
        if (lower_name.ends_with(e.name)) return &e;
    return nullptr;
}

// The names joined by `separator`, those with gzip == `gzip` only.
inline std::string scene_extension_names(bool gzip, const char* separator) {
    std::string names;
    for (const SceneExtension& e : kSceneExtensions)
        if (e.gzip == gzip) names += (names.empty() ? "" : separator) + std::string(e.name);
    return names;
}

}  // namespace vr
