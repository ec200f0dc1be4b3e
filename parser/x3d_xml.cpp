#include "parser/x3d_xml.h"

namespace vr {

ClassicResult read_x3d_xml(LoadedScene& scene, uint32_t file, const LoadLimits&) {
    ClassicResult result;
    scene.diagnostics.error({file, 0}, "X3D XML files are not supported yet");
    result.ok = false;
    return result;
}

}  // namespace vr
