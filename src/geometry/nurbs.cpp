// NURBS evaluation (de Boor's algorithm), knot checks and the tessellation rule (nurbs.h).
#include "geometry/nurbs.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace vr {

namespace {

bool finite(const Vec3& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// The knot span k with knots[k] <= t < knots[k + 1] and degree <= k < count (the last non-empty
// span for t at the domain's end).
int find_span(const std::vector<double>& knots, int degree, int count, double t) {
    if (t >= knots[size_t(count)]) {
        int k = count - 1;
        while (k > degree && knots[size_t(k)] >= knots[size_t(k) + 1]) --k;
        return k;
    }
    const auto first = knots.begin() + degree + 1, last = knots.begin() + count;
    return int(std::upper_bound(first, last, t) - knots.begin()) - 1;
}

// de Boor's algorithm on the degree + 1 homogeneous points d[0..p] that act on span k; returns the
// point and, from the last level's two points, the derivative p (d1 - d0) / (t[k+1] - t[k]).
void de_boor(Vec4* d, const std::vector<double>& knots, int k, int p, double t, Vec4& value,
             Vec4& derivative) {
    derivative = Vec4(0.0);
    for (int r = 1; r <= p; ++r) {
        if (r == p) {
            const double span = knots[size_t(k) + 1] - knots[size_t(k)];
            derivative = double(p) * (d[p] - d[p - 1]) / span;
        }
        for (int j = p; j >= r; --j) {
            const double lo = knots[size_t(j + k - p)], hi = knots[size_t(j + 1 + k - r)];
            const double alpha = hi > lo ? (t - lo) / (hi - lo) : 0.0;
            d[j] = (1.0 - alpha) * d[j - 1] + alpha * d[j];
        }
    }
    value = d[p];
}

// The rational point and derivative from homogeneous ones: C = A / w, C' = (A' - w' C) / w.
void project(const Vec4& a, const Vec4& da, Vec3& point, Vec3& derivative) {
    point = Vec3(a) / a.w;
    derivative = (Vec3(da) - da.w * point) / a.w;
}

std::vector<Vec4> homogeneous(const std::vector<Vec3>& points, const std::vector<double>& weights) {
    std::vector<Vec4> out(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
        const double w = weights.size() == points.size() ? weights[i] : 1.0;
        out[i] = Vec4(points[i] * w, w);
    }
    return out;
}

}  // namespace

std::vector<double> usable_knots(const std::vector<double>& knots, int count, int order,
                                 NodeReport& report, const char* what) {
    const size_t want = size_t(count) + size_t(order);
    bool ok = knots.size() == want;
    for (size_t i = 0; ok && i < knots.size(); ++i)
        ok = std::isfinite(knots[i]) && (i == 0 || knots[i] >= knots[i - 1]);
    if (ok) ok = knots[size_t(order) - 1] < knots[size_t(count)];
    if (ok) return knots;
    if (!knots.empty())
        report.warn(std::string(what) + "-knots",
                    std::string(what) + " has " + std::to_string(knots.size()) + " knots where " +
                        std::to_string(want) +
                        " non-decreasing ones are needed; a uniform clamped knot vector is used");
    // Clamped uniform: `order` zeros, the interior evenly spaced, `order` ones.
    std::vector<double> out(want);
    const int interior = count - order;
    for (size_t i = 0; i < want; ++i) {
        const int step = std::clamp(int(i) - order + 1, 0, interior + 1);
        out[i] = double(step) / double(interior + 1);
    }
    return out;
}

bool make_curve(const sg::NurbsCurve& c, RationalCurve& out, NodeReport& report, const char* what) {
    const int order = c.polyline ? 2 : c.order;
    const int count = int(c.points.size());
    if (order > kNurbsMaxOrder) {
        report.warn(std::string(what) + "-order", std::string(what) + " has an order above " +
                                                      std::to_string(kNurbsMaxOrder) +
                                                      "; not drawn");
        return false;
    }
    if (order < 2 || count < order) {
        report.warn(std::string(what) + "-order", std::string(what) + " needs at least `order` (" +
                                                      std::to_string(order) +
                                                      ", at least 2) control points and has " +
                                                      std::to_string(count) + "; not drawn");
        return false;
    }
    for (const Vec3& p : c.points)
        if (!finite(p)) {
            report.warn("non-finite", std::string(what) +
                                          " has a NaN or infinite control point; "
                                          "not drawn");
            return false;
        }
    bool weights_ok = c.weights.empty() || c.weights.size() == c.points.size();
    for (double w : c.weights) weights_ok = weights_ok && w > 0.0 && std::isfinite(w);
    if (!weights_ok)
        report.warn("weights", std::string(what) +
                                   " weights must be positive, one a control point; all are 1");
    out.points = homogeneous(c.points, weights_ok ? c.weights : std::vector<double>());
    out.degree = order - 1;
    // A polyline's knots put a knot at every point: straight segments through them.
    out.knots =
        usable_knots(c.polyline ? std::vector<double>() : c.knots, count, order, report, what);
    return true;
}

CurveSample evaluate(const RationalCurve& c, double t) {
    const int p = c.degree, n = int(c.points.size());
    t = std::clamp(t, c.start(), c.end());
    const int k = find_span(c.knots, p, n, t);
    Vec4 d[kNurbsMaxOrder];  // make_curve and make_patch check the order
    for (int j = 0; j <= p; ++j) d[j] = c.points[size_t(k - p + j)];
    Vec4 a, da;
    de_boor(d, c.knots, k, p, t, a, da);
    CurveSample s;
    project(a, da, s.position, s.derivative);
    return s;
}

SurfaceSample evaluate(const RationalSurface& s, double u, double v) {
    const int p = s.u_degree, q = s.v_degree;
    u = std::clamp(u, s.u_start(), s.u_end());
    v = std::clamp(v, s.v_start(), s.v_end());
    const int ku = find_span(s.u_knots, p, s.u_count, u);
    const int kv = find_span(s.v_knots, q, s.v_count, v);
    // de Boor in u along each of the q + 1 rows that act on v's span, then in v over the rows'
    // points (S and dS/dv) and over their u derivatives (dS/du).
    Vec4 rows[kNurbsMaxOrder], row_du[kNurbsMaxOrder];
    for (int j = 0; j <= q; ++j) {
        Vec4 d[kNurbsMaxOrder];
        const size_t row = size_t(kv - q + j) * size_t(s.u_count);
        for (int i = 0; i <= p; ++i) d[i] = s.points[row + size_t(ku - p + i)];
        de_boor(d, s.u_knots, ku, p, u, rows[j], row_du[j]);
    }
    Vec4 a, da_dv, da_du, unused;
    de_boor(rows, s.v_knots, kv, q, v, a, da_dv);
    de_boor(row_du, s.v_knots, kv, q, v, da_du, unused);
    SurfaceSample out;
    project(a, da_du, out.position, out.du);
    out.dv = (Vec3(da_dv) - da_dv.w * out.position) / a.w;
    return out;
}

std::vector<double> direction_parameters(const std::vector<double>& knots, int degree, int count,
                                         int tessellation, double tolerance,
                                         const SampleAt& sample) {
    const double start = knots[size_t(degree)], end = knots[size_t(count)];
    std::vector<double> out;
    if (tessellation != 0) {
        const long segments =
            std::clamp<long>(tessellation > 0 ? long(tessellation) : -long(tessellation) * count, 1,
                             kNurbsMaxSegments);
        for (long i = 0; i <= segments; ++i)
            out.push_back(start + (end - start) * double(i) / double(segments));
        return out;
    }
    // Span by span: segments enough for h^2 max|C''| / 8 <= tolerance, the second derivative
    // estimated from second differences at kProbe + 1 points of the span.
    constexpr int kProbe = 32;
    std::vector<int> per_span;
    int total = 0;
    std::vector<Vec3> a, b, c;
    for (int k = degree; k < count; ++k) {
        const double lo = knots[size_t(k)], hi = knots[size_t(k) + 1];
        if (!(hi > lo)) continue;
        const double h = (hi - lo) / kProbe;
        double curvature = 0.0;  // max |C''|
        sample(lo, a);
        sample(lo + h, b);
        for (int i = 2; i <= kProbe; ++i) {
            sample(lo + i * h, c);
            for (size_t j = 0; j < a.size() && j < b.size() && j < c.size(); ++j)
                curvature = std::max(curvature, glm::length(a[j] - 2.0 * b[j] + c[j]) / (h * h));
            std::swap(a, b);
            std::swap(b, c);
        }
        const double length = hi - lo;
        const double need = std::sqrt(curvature * length * length / (8.0 * tolerance));
        const int segments =
            std::isfinite(need) ? std::clamp(int(std::ceil(need)), 1, kNurbsMaxSegments) : 1;
        per_span.push_back(segments);
        total += segments;
    }
    // At least X3D's 2n segments over the domain (27.4.2 c).
    const double floor_scale = total < 2 * count ? double(2 * count) / std::max(total, 1) : 1.0;
    // Within the cap: scale down evenly.
    const double cap_scale =
        total * floor_scale > kNurbsMaxSegments ? kNurbsMaxSegments / (total * floor_scale) : 1.0;
    size_t span = 0;
    out.push_back(start);
    for (int k = degree; k < count; ++k) {
        const double lo = knots[size_t(k)], hi = knots[size_t(k) + 1];
        if (!(hi > lo)) continue;
        const int segments =
            std::max(1, int(std::ceil(per_span[span++] * floor_scale * cap_scale)));
        for (int i = 1; i <= segments; ++i) out.push_back(lo + (hi - lo) * double(i) / segments);
    }
    return out;
}

std::vector<Vec3> curve_polyline(const sg::NurbsCurve& c, NodeReport& report, const char* what) {
    if (c.polyline) {
        for (const Vec3& p : c.points)
            if (!finite(p)) {
                report.warn("non-finite",
                            std::string(what) + " has a NaN or infinite point; not drawn");
                return {};
            }
        return c.points;
    }
    RationalCurve curve;
    if (!make_curve(c, curve, report, what)) return {};
    Vec3 lo(kInf), hi(-kInf);
    for (const Vec3& p : c.points) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const double tolerance = kNurbsChordTolerance * std::max(glm::length(hi - lo), 1e-300);
    const auto params = direction_parameters(
        curve.knots, curve.degree, int(curve.points.size()), c.tessellation, tolerance,
        [&](double t, std::vector<Vec3>& out) { out.assign(1, evaluate(curve, t).position); });
    std::vector<Vec3> out;
    out.reserve(params.size());
    for (double t : params) out.push_back(evaluate(curve, t).position);
    return out;
}

}  // namespace vr
