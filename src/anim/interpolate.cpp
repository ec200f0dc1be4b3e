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

// `q` as axis and angle; no rotation keeps the axis `a` (the first key's, as the file wrote it).
void to_axis_angle(const Quat& q, const double* a, double* out) {
    const double s = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
    if (!(s > 0.0)) {
        out[0] = a[0], out[1] = a[1], out[2] = a[2], out[3] = 0.0;
        return;
    }
    out[0] = q.x / s, out[1] = q.y / s, out[2] = q.z / s;
    out[3] = 2.0 * std::atan2(s, q.w);  // in [0, 2 pi); q.w >= 0 on the shorter arc keeps it <= pi
}

Quat mul(const Quat& a, const Quat& b) {
    return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
            a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
            a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
            a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

Quat conj(const Quat& q) { return {q.w, -q.x, -q.y, -q.z}; }

// log of a unit quaternion: the pure quaternion (half angle) * axis.
Quat log_unit(const Quat& q) {
    const double s = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
    if (!(s > 0.0)) return {0.0, 0.0, 0.0, 0.0};
    const double k = std::atan2(s, q.w) / s;
    return {0.0, q.x * k, q.y * k, q.z * k};
}

Quat exp_pure(const Quat& v) {
    const double a = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    if (!(a > 0.0)) return {1.0, 0.0, 0.0, 0.0};
    const double k = std::sin(a) / a;
    return {std::cos(a), v.x * k, v.y * k, v.z * k};
}

// The key interval holding `fraction`, key[i] <= fraction < key[i + 1], for fractions strictly
// inside (key[0], key[n - 1]).
size_t interval_of(std::span<const double> key, double fraction) {
    return size_t(std::upper_bound(key.begin(), key.end(), fraction) - key.begin()) - 1;
}

double length(const double* v, size_t width) {
    double sum = 0.0;
    for (size_t c = 0; c < width; ++c) sum += v[c] * v[c];
    return std::sqrt(sum);
}

}  // namespace

void blend_rotation(const double* a, const double* b, double t, double* out) {
    const Quat qa = from_axis_angle(a);
    Quat qb = from_axis_angle(b);
    if (dot(qa, qb) < 0.0) qb = {-qb.w, -qb.x, -qb.y, -qb.z};  // the shorter arc
    to_axis_angle(slerp(qa, qb, t), a, out);
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
    const size_t i = interval_of(key, fraction);
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

namespace {

// The spline's tangent T_j at key j (before the key-interval scaling), into `t`.
struct Spline {
    std::span<const double> key, value, velocity;
    size_t n, width, given;  // given: velocities, n or 2 (else none is used)
    bool wrap, normalize;
    double total = 0.0;  // D = sum |v_j+1 - v_j|, for normalizeVelocity

    const double* at(size_t j) const { return value.data() + j * width; }
    double h(size_t j) const { return key[j + 1] - key[j]; }

    void tangent(size_t j, double* t) const {
        const bool end = j == 0 || j == n - 1;
        if (given == n || (given == 2 && end)) {
            const double* v = velocity.data() + (given == n ? j : j == 0 ? 0 : 1) * width;
            const double len = length(v, width);
            // A zero velocity has no direction to scale: it stays 0.
            const double scale = !normalize ? 1.0 : len > 0.0 ? total / len : 0.0;
            for (size_t c = 0; c < width; ++c) t[c] = v[c] * scale;
            return;
        }
        const double *before = end ? at(n - 2) : at(j - 1), *after = end ? at(1) : at(j + 1);
        for (size_t c = 0; c < width; ++c) t[c] = end && !wrap ? 0.0 : 0.5 * (after[c] - before[c]);
    }
};

}  // namespace

std::vector<double> interpolate_spline(std::span<const double> key,
                                       std::span<const double> key_value, size_t width,
                                       const SplineOptions& options, double fraction) {
    const size_t n = key.size();
    if (n == 0 || width == 0 || key_value.size() < n * width) return {};
    std::vector<double> out(width);
    if (!(fraction > key[0]) || n == 1 || fraction >= key[n - 1]) {  // NaN: the first value
        const size_t j = fraction >= key[n - 1] ? n - 1 : 0;
        std::copy_n(key_value.data() + j * width, width, out.begin());
        return out;
    }
    Spline sp{key, key_value, options.key_velocity, n, width, 0, false, options.normalize_velocity};
    const size_t given =
        options.key_velocity.size() % width == 0 ? options.key_velocity.size() / width : 0;
    sp.given = given == n || given == 2 ? given : 0;
    sp.wrap = options.closed && sp.given == 0 && n >= 3 &&
              std::equal(sp.at(0), sp.at(0) + width, sp.at(n - 1));
    if (sp.normalize && sp.given != 0) {
        std::vector<double> d(width);
        for (size_t j = 0; j + 1 < n; ++j) {
            for (size_t c = 0; c < width; ++c) d[c] = sp.at(j + 1)[c] - sp.at(j)[c];
            sp.total += length(d.data(), width);
        }
    }
    const size_t i = interval_of(key, fraction);
    // The velocity stays continuous across key i when the tangents scale with the intervals
    // on either side; an open curve's ends have one interval only, and keep T as it is.
    const double before_i = i > 0 ? sp.h(i - 1) : sp.h(n - 2);
    const double after_next = i + 2 < n ? sp.h(i + 1) : sp.h(0);
    const bool inner_i = i > 0 || sp.wrap, inner_next = i + 2 < n || sp.wrap;
    const double f_out = inner_i ? 2.0 * sp.h(i) / (before_i + sp.h(i)) : 1.0;
    const double f_in = inner_next ? 2.0 * sp.h(i) / (sp.h(i) + after_next) : 1.0;
    std::vector<double> t0(width), t1(width);
    sp.tangent(i, t0.data());
    sp.tangent(i + 1, t1.data());
    const double s = (fraction - key[i]) / sp.h(i), s2 = s * s, s3 = s2 * s;
    const double h00 = 2.0 * s3 - 3.0 * s2 + 1.0, h01 = 3.0 * s2 - 2.0 * s3,
                 h10 = s3 - 2.0 * s2 + s, h11 = s3 - s2;
    const double *a = sp.at(i), *b = sp.at(i + 1);
    for (size_t c = 0; c < width; ++c)
        out[c] = h00 * a[c] + h01 * b[c] + h10 * f_out * t0[c] + h11 * f_in * t1[c];
    return out;
}

std::vector<double> interpolate_squad(std::span<const double> key,
                                      std::span<const double> key_value, double fraction) {
    const size_t n = key.size();
    if (n == 0 || key_value.size() < n * 4) return {};
    std::vector<double> out(4);
    if (!(fraction > key[0]) || n == 1 || fraction >= key[n - 1]) {
        const size_t j = fraction >= key[n - 1] ? n - 1 : 0;
        std::copy_n(key_value.data() + j * 4, 4, out.begin());
        return out;
    }
    const size_t i = interval_of(key, fraction);
    // Each key on the side of the one before it, from the first key on, so that every interval
    // takes its shorter arc.
    std::vector<Quat> q(std::min(n, i + 3));
    for (size_t j = 0; j < q.size(); ++j) {
        q[j] = from_axis_angle(key_value.data() + j * 4);
        if (j > 0 && dot(q[j - 1], q[j]) < 0.0) q[j] = {-q[j].w, -q[j].x, -q[j].y, -q[j].z};
    }
    auto inner = [&](size_t j) {  // s_j
        if (j == 0 || j == n - 1) return q[j];
        const Quat inv = conj(q[j]);
        const Quat a = log_unit(mul(inv, q[j + 1])), b = log_unit(mul(inv, q[j - 1]));
        return mul(q[j],
                   exp_pure({0.0, -0.25 * (a.x + b.x), -0.25 * (a.y + b.y), -0.25 * (a.z + b.z)}));
    };
    const double u = (fraction - key[i]) / (key[i + 1] - key[i]);
    const Quat result =
        slerp(slerp(q[i], q[i + 1], u), slerp(inner(i), inner(i + 1), u), 2.0 * u * (1.0 - u));
    to_axis_angle(result, key_value.data() + i * 4, out.data());
    return out;
}

std::optional<double> ease_in_ease_out(std::span<const double> key, std::span<const double> ease,
                                       double fraction) {
    const size_t n = key.size();
    if (n == 0) return std::nullopt;
    if (!(fraction > key[0]) || n == 1) return 0.0;
    if (fraction >= key[n - 1]) return 1.0;
    const size_t i = interval_of(key, fraction), pairs = ease.size() / 2;
    auto pair = [&](size_t j, int c) {
        return pairs == 0 ? 0.0 : ease[std::min(j, pairs - 1) * 2 + c];
    };
    double e_out = pair(i, 1), e_in = pair(i + 1, 0);
    const double u = (fraction - key[i]) / (key[i + 1] - key[i]), sum = e_out + e_in;
    if (sum < 0.0) return u;
    if (sum > 1.0) e_out /= sum, e_in /= sum;
    const double t = 1.0 / (2.0 - e_out - e_in);  // e_out + e_in <= 1: t in [0.5, 1]
    if (u < e_out) return t / e_out * u * u;
    // "<=" where the spec writes "<": with eIn = 0 the last branch would divide by 0 at u = 1.
    if (u <= 1.0 - e_in) return t * (2.0 * u - e_out);
    return 1.0 - t * (1.0 - u) * (1.0 - u) / e_in;
}

}  // namespace vr
