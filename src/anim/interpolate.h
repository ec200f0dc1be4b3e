// The interpolator nodes' functions (VRML97 6.x / X3D 19.4), on plain numbers so that each can be
// checked alone: key fractions, key values (components per value, values per key) and a fraction
// in, the value_changed out.
#pragma once
#include <optional>
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

// X3D 19.2.4 / 19.4.11: the Hermite spline of SplinePositionInterpolator(2D) and
// SplineScalarInterpolator, `width` numbers a value. On key interval [t_i, t_i+1], s = (f - t_i) /
// (t_i+1 - t_i) and v(s) = h00 v_i + h01 v_i+1 + h10 T0_i + h11 T1_i+1 (h00 = 2s^3 - 3s^2 + 1,
// h01 = 3s^2 - 2s^3, h10 = s^3 - 2s^2 + s, h11 = s^3 - s^2). The tangent T_i is keyVelocity_i
// when keyVelocity holds one value per key; with two values they are the end tangents; else the
// ends get 0 (an open curve) or (v_1 - v_n-2) / 2 (closed, only when keyValue's first and last
// values are equal), the inner keys (v_i+1 - v_i-1) / 2. normalizeVelocity scales each given
// velocity to the length D = sum |v_i+1 - v_i|. Inner (and closed-end) tangents scale with the key
// intervals so that the velocity is continuous: T0_i = 2 h_i / (h_i-1 + h_i) T_i as the interval
// after key i starts, T1_i = 2 h_i-1 / (h_i-1 + h_i) T_i as the one before it ends (h_i =
// t_i+1 - t_i; a closed curve's h_-1 is h_n-2). Outside the keys, as interpolate().
struct SplineOptions {
    std::span<const double> key_velocity;  // width numbers per velocity
    bool closed = false;
    bool normalize_velocity = false;
};
std::vector<double> interpolate_spline(std::span<const double> key,
                                       std::span<const double> key_value, size_t width,
                                       const SplineOptions& options, double fraction);

// X3D 19.4.9 SquadOrientationInterpolator on axis-angle keyValues (4 numbers each): on key
// interval i, squad(q_i, q_i+1, s_i, s_i+1, u) = slerp(slerp(q_i, q_i+1, u), slerp(s_i, s_i+1, u),
// 2u(1 - u)) with s_i = q_i exp(-(log(q_i^-1 q_i+1) + log(q_i^-1 q_i-1)) / 4) (s = q at the ends).
// Each key's quaternion is first put on the side of the previous one (the shorter arcs).
std::vector<double> interpolate_squad(std::span<const double> key,
                                      std::span<const double> key_value, double fraction);

// X3D 19.4.2 EaseInEaseOut's modifiedFraction_changed: on key interval i, u = (f - t_i) / (t_i+1
// - t_i), eOut = easeInEaseOut[i].y, eIn = easeInEaseOut[i+1].x, S = eOut + eIn. S < 0: u; S > 1
// divides both by S; then with t = 1 / (2 - eOut - eIn): t u^2 / eOut for u < eOut, t (2u - eOut)
// up to 1 - eIn, 1 - t (1 - u)^2 / eIn after. Like the spec (and X_ITE), the result is the
// fraction within the interval, in [0, 1]; before the first key 0, after the last 1. Fewer pairs
// than keys repeat the last pair (none: 0 0, linear). Nothing when there are no keys.
std::optional<double> ease_in_ease_out(std::span<const double> key, std::span<const double> ease,
                                       double fraction);

// The blends of two values at t in [0, 1] (t = 0 gives a, t = 1 gives b), for one value each.
void blend_rotation(const double* a, const double* b, double t, double* out);  // x y z angle
void blend_unit_vector(const double* a, const double* b, double t, double* out);
void blend_hsv(const double* a, const double* b, double t, double* out);  // RGB in and out

}  // namespace vr
