#include "anim/geo_position.h"

#include <cmath>

#include "anim/interpolate.h"
#include "core/geo.h"

namespace vr {

namespace {

geo::System system_of(const NodeTree& tree, NodeId node, std::vector<std::string>& problems) {
    const FieldView words = tree.get(node, "geoSystem");
    const std::vector<std::string> list(words.strings.begin(), words.strings.end());
    return geo::parse_system(list, problems);
}

}  // namespace

std::optional<GeoPositionValue> geo_position_at(const NodeTree& tree, NodeId node, double fraction,
                                                std::vector<std::string>& problems) {
    const geo::System system = system_of(tree, node, problems);
    const std::vector<double> blended =
        interpolate(tree.get(node, "key").numbers, tree.get(node, "keyValue").numbers, 3,
                    Blend::Linear, fraction);
    if (blended.size() != 3) return std::nullopt;
    GeoPositionValue out;
    out.geovalue = Vec3(blended[0], blended[1], blended[2]);
    geo::Origin origin;
    const FieldView origin_field = tree.get(node, "geoOrigin");
    if (!origin_field.nodes.empty() && origin_field.nodes[0] != kNullNode &&
        tree.type_name(origin_field.nodes[0]) == "GeoOrigin") {
        const NodeId o = origin_field.nodes[0];
        const FieldView coords = tree.get(o, "geoCoords");
        if (coords.numbers.size() == 3)
            origin = geo::make_origin(system_of(tree, o, problems),
                                      Vec3(coords.numbers[0], coords.numbers[1], coords.numbers[2]),
                                      tree.get_bool(o, intern("rotateYUp")));
    }
    const Vec3 geocentric = geo::to_geocentric(system, out.geovalue);
    if (!std::isfinite(geocentric.x)) return std::nullopt;
    out.value = origin.world_point(geocentric);
    return out;
}

}  // namespace vr
