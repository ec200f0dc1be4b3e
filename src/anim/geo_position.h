// X3D 25.4.7 GeoPositionInterpolator: keyValue holds coordinates of the node's geoSystem, blended
// linearly in that system (geovalue_changed); value_changed is the blended point in world
// coordinates (geocentric, less the node's GeoOrigin and turned by its rotateYUp).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "core/math.h"
#include "parser/node_tree.h"

namespace vr {

struct GeoPositionValue {
    Vec3 geovalue;  // in the node's geoSystem
    Vec3 value;     // world coordinates
};
// Nothing when the node sends nothing (no keys, too few values, a point outside its system);
// `problems` gets one sentence for each geoSystem word it cannot use.
std::optional<GeoPositionValue> geo_position_at(const NodeTree& tree, NodeId node, double fraction,
                                                std::vector<std::string>& problems);

}  // namespace vr
