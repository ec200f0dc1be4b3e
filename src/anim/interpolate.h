// The interpolator nodes' functions (VRML97 6.x / X3D 19.4), on plain numbers so that each can be
// checked alone: key fractions, key values (components per value, values per key) and a fraction
// in, the value_changed out.
#pragma once
#include <span>
#include <vector>

namespace vr {

// What an interpolator blends: component-wise linear (Scalar, Position, Coordinate, the 2D
// ones), HSV (Color, as both specifications say), the shortest-arc slerp of axis-angle rotations
// (Orientation) or the slerp of unit vectors renormalised (Normal).
enum class Blend { Linear, Hsv, Rotation, UnitVector };

// value_changed for `fraction`: keyValue[0] at or before key[0], the last value at or after the
// last key, else the blend of the two values around it (keys are non-decreasing; of equal keys the
// later one's value holds from that key on). `width` numbers make one key's value (3 for SFVec3f,
// 3 m for an MFVec3f of m points). Empty when the node can produce nothing (no keys, or fewer
// values than keys * width).
std::vector<double> interpolate(std::span<const double> key, std::span<const double> key_value,
                                size_t width, Blend blend, double fraction);

// The blends of two values at t in [0, 1] (t = 0 gives a, t = 1 gives b), for one value each.
void blend_rotation(const double* a, const double* b, double t, double* out);  // x y z angle
void blend_unit_vector(const double* a, const double* b, double t, double* out);
void blend_hsv(const double* a, const double* b, double t, double* out);  // RGB in and out

}  // namespace vr
