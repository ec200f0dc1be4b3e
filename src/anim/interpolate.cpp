#include "anim/interpolate.h"

#include <algorithm>
#include <cmath>

namespace vr {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Quat {
    double w, x, y, z;
};

Quat from_axis_angle(const double* r) {
    const double len = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (!(len > 0.0)) return {1.0, 0.0, 0.0, 0.0};  // no axis: no rotation
    const double s = std::sin(0.5 * r[3]) / len;
    return {std::cos(0.5 * r[3]), r[0] * s, r[1] * s, r[2] * s};
}

double dot(const Quat& a, const Quat& b) { return a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z; }

// Spherical interpolation of unit 4-vectors a and b (their dot product >= 0): the angle comes from
// atan2 of the chord lengths, exact also for nearly equal inputs where acos(dot) loses half the
// digits.
Quat slerp(const Quat& a, const Quat& b, double t) {
    const double dw = a.w - b.w, dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
    const double sw = a.w + b.w, sx = a.x + b.x, sy = a.y + b.y, sz = a.z + b.z;
    const double theta = 2.0 * std::atan2(std::sqrt(dw * dw + dx * dx + dy * dy + dz * dz),
                                          std::sqrt(sw * sw + sx * sx + sy * sy + sz * sz));
    double ca = 1.0 - t, cb = t;
    if (theta > 1e-9) {  // below that, sin(t theta) / sin(theta) = t to double precision
        const double s = std::sin(theta);
        ca = std::sin((1.0 - t) * theta) / s;
        cb = std::sin(t * theta) / s;
    }
    Quat q{ca * a.w + cb * b.w, ca * a.x + cb * b.x, ca * a.y + cb * b.y, ca * a.z + cb * b.z};
    const double n = std::sqrt(dot(q, q));
    return {q.w / n, q.x / n, q.y / n, q.z / n};
}

void rgb_to_hsv(const double* c, double* hsv) {
    const double mx = std::max({c[0], c[1], c[2]}), mn = std::min({c[0], c[1], c[2]});
    const double d = mx - mn;
    double h = 0.0;
    if (d > 0.0) {
        if (mx == c[0])
            h = (c[1] - c[2]) / d;
        else if (mx == c[1])
            h = 2.0 + (c[2] - c[0]) / d;
        else
            h = 4.0 + (c[0] - c[1]) / d;
        h /= 6.0;
        if (h < 0.0) h += 1.0;
    }
    hsv[0] = h;  // in [0, 1): a turn
    hsv[1] = mx > 0.0 ? d / mx : 0.0;
    hsv[2] = mx;
}

void hsv_to_rgb(const double* hsv, double* c) {
    const double h = 6.0 * (hsv[0] - std::floor(hsv[0])), s = hsv[1], v = hsv[2];
    const int sector = std::min(5, int(h));
    const double f = h - sector;
    const double p = v * (1.0 - s), q = v * (1.0 - s * f), r = v * (1.0 - s * (1.0 - f));
    const double table[6][3] = {{v, r, p}, {q, v, p}, {p, v, r}, {p, q, v}, {r, p, v}, {v, p, q}};
    for (int i = 0; i < 3; ++i) c[i] = table[sector][i];
}

}  // namespace

void blend_rotation(const double* a, const double* b, double t, double* out) {
    const Quat qa = from_axis_angle(a);
    Quat qb = from_axis_angle(b);
    if (dot(qa, qb) < 0.0) qb = {-qb.w, -qb.x, -qb.y, -qb.z};  // the shorter arc
    const Quat q = slerp(qa, qb, t);
    const double s = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
    if (!(s > 0.0)) {  // no rotation: keep the first key's axis, as the file wrote it
        out[0] = a[0], out[1] = a[1], out[2] = a[2], out[3] = 0.0;
        return;
    }
    out[0] = q.x / s, out[1] = q.y / s, out[2] = q.z / s;
    out[3] = 2.0 * std::atan2(s, q.w);  // in [0, 2 pi); q.w >= 0 on the shorter arc keeps it <= pi
}

void blend_unit_vector(const double* a, const double* b, double t, double* out) {
    const double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]),
                 lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    if (!(la > 0.0) || !(lb > 0.0)) {  // a zero normal has no direction to turn
        for (int i = 0; i < 3; ++i) out[i] = a[i] + t * (b[i] - a[i]);
        return;
    }
    const Quat qa{0.0, a[0] / la, a[1] / la, a[2] / la}, qb{0.0, b[0] / lb, b[1] / lb, b[2] / lb};
    // Opposite normals have no unique arc: the spec leaves it undefined; the chord's midpoint
    // would be 0, so the slerp's atan2 form (theta = pi) picks sin-weights, which stay finite.
    const Quat q = slerp(qa, qb, t);
    out[0] = q.x, out[1] = q.y, out[2] = q.z;
}

void blend_hsv(const double* a, const double* b, double t, double* out) {
    double ha[3], hb[3];
    rgb_to_hsv(a, ha);
    rgb_to_hsv(b, hb);
    // A grey has no hue: it takes the other colour's, so that red to grey only desaturates.
    if (ha[1] == 0.0) ha[0] = hb[0];
    if (hb[1] == 0.0) hb[0] = ha[0];
    double dh = hb[0] - ha[0];
    if (dh > 0.5) dh -= 1.0;  // the shorter way round the hue circle
    if (dh < -0.5) dh += 1.0;
    const double hsv[3] = {ha[0] + t * dh, ha[1] + t * (hb[1] - ha[1]),
                           ha[2] + t * (hb[2] - ha[2])};
    hsv_to_rgb(hsv, out);
}

std::vector<double> interpolate(std::span<const double> key, std::span<const double> key_value,
                                size_t width, Blend blend, double fraction) {
    const size_t n = key.size();
    if (n == 0 || width == 0 || key_value.size() < n * width) return {};
    std::vector<double> out(width);
    auto value = [&](size_t i) { return key_value.data() + i * width; };
    if (!(fraction > key[0]) || n == 1) {  // at or before the first key (NaN too)
        std::copy_n(value(0), width, out.begin());
        return out;
    }
    if (fraction >= key[n - 1]) {
        std::copy_n(value(n - 1), width, out.begin());
        return out;
    }
    // key[i] <= fraction < key[i + 1]
    const size_t i = size_t(std::upper_bound(key.begin(), key.end(), fraction) - key.begin()) - 1;
    const double t = (fraction - key[i]) / (key[i + 1] - key[i]);
    const double *a = value(i), *b = value(i + 1);
    const size_t step = blend == Blend::Rotation ? 4 : blend == Blend::Linear ? 1 : 3;
    for (size_t c = 0; c + step <= width; c += step) {
        switch (blend) {
            case Blend::Linear:
                out[c] = a[c] + t * (b[c] - a[c]);
                break;
            case Blend::Hsv:
                blend_hsv(a + c, b + c, t, &out[c]);
                break;
            case Blend::Rotation:
                blend_rotation(a + c, b + c, t, &out[c]);
                break;
            case Blend::UnitVector:
                blend_unit_vector(a + c, b + c, t, &out[c]);
                break;
        }
    }
    return out;
}

}  // namespace vr
