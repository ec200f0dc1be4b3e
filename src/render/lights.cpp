#include "render/lights.h"

#include <algorithm>
#include <cmath>

namespace vr {

double light_attenuation(const Light& light, double d) {
    const Vec3& a = light.attenuation;
    double denom = a.x + a.y * d + a.z * d * d;
    if (!(denom >= 1.0)) denom = 1.0;  // also catches NaN
    return 1.0 / denom;
}

double spot_factor(const Light& light, const Vec3& from_light) {
    double cos_angle = std::clamp(glm::dot(light.direction, from_light), -1.0, 1.0);
    double angle = std::acos(cos_angle);
    const double cutoff = light.cutoff_angle, beam = light.beam_width;
    if (!(angle < cutoff)) return 0.0;
    if (beam >= cutoff || angle <= beam) return 1.0;
    return (cutoff - angle) / (cutoff - beam);
}

LightIncidence light_incidence(const Light& light, const Vec3& p) {
    LightIncidence inc;
    if (light.kind == LightKind::Directional) {
        inc.to_light = -light.direction;
        inc.distance = kInf;
        inc.factor = 1.0;
        return inc;
    }
    Vec3 v = light.position - p;
    double d = glm::length(v);
    if (!(d <= light.radius)) return inc;  // beyond the radius, or not finite
    inc.distance = d;
    inc.to_light = d > 0.0 ? v / d : -light.direction;
    double f = light_attenuation(light, d);
    if (light.kind == LightKind::Spot) f *= spot_factor(light, -inc.to_light);
    inc.factor = f;
    return inc;
}

}  // namespace vr
