// Light geometry of the VRML97 lighting model (4.14.4; X3D 17.2.2): where a light is seen from a
// point and the factor on_i * attenuation_i * spot_i that scales all of its terms there.
#pragma once
#include "core/math.h"
#include "render/flat_scene.h"

namespace vr {

struct LightIncidence {
    Vec3 to_light{0.0, 0.0, 1.0};  // unit L, from the point towards the light
    double distance = kInf;        // to a point or spot light; infinite for directional lights
    double factor = 0.0;           // on * attenuation * spot; 0: the light does not reach the point
};

// 1 / max(c1 + c2*d + c3*d^2, 1).
double light_attenuation(const Light& light, double distance);

// Spot cone: 1 inside beamWidth, 0 at and beyond cutOffAngle, and in between X3D's linear ramp
// (cutOffAngle - angle) / (cutOffAngle - beamWidth). (VRML97 leaves the in-between falloff loosely
// specified; X3D's ramp is exact and continuous, so it is used.) A beamWidth at or beyond the
// cutOffAngle gives a hard edge at the cutOffAngle. `from_light` is the unit vector from the light
// to the point.
double spot_factor(const Light& light, const Vec3& from_light);

// Point and spot lights light only geometry within their radius (VRML97 PointLight/SpotLight:
// `radius`), and then everything of theirs, ambient term included, is scaled by attenuation and
// spot. Directional lights: factor 1. Expects light.direction to be unit length.
LightIncidence light_incidence(const Light& light, const Vec3& p);

}  // namespace vr
