#include "render/soft_light.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace vr {
namespace {

using RingCap = CapScratch::RingCap;

// Half-width of the arc that `cap` closes on the ring at angle theta (given as cos, sin) about the
// axis: cos(beta) = (cos a - cos t cos c) / (sin t sin c), clamped. A degenerate ring or cap axis
// (sin = 0) gives all or nothing; the tie (the axis on the cap's rim) gives pi/2, the limit of
// nearby rings, so that a bracket from endpoint values stays a bracket.
double arc_half_width(const RingCap& cap, double cos_t, double sin_t) {
    const double num = cap.cos_a - cos_t * cap.cos_c;
    const double den = sin_t * cap.sin_c;
    if (!(den > 0.0)) return num < 0.0 ? kPi : (num > 0.0 ? 0.0 : 0.5 * kPi);
    if (num >= den) return 0.0;
    if (num <= -den) return kPi;
    return std::acos(num / den);
}

// The open share of a ring whose caps close the arcs phi_i +- beta_i.
double ring_open(const std::vector<RingCap>& caps, const double* beta,
                 std::vector<std::pair<double, double>>& arcs) {
    constexpr double kTwoPi = 2.0 * kPi;
    arcs.clear();
    for (size_t i = 0; i < caps.size(); ++i) {
        if (!(beta[i] > 0.0)) continue;
        if (beta[i] >= kPi) return 0.0;
        double start = caps[i].phi - beta[i];  // phi in [0, 2 pi): start in [-pi, 2 pi)
        if (start < 0.0) start += kTwoPi;
        const double end = start + 2.0 * beta[i];
        if (end > kTwoPi) {
            arcs.emplace_back(start, kTwoPi);
            arcs.emplace_back(0.0, end - kTwoPi);
        } else {
            arcs.emplace_back(start, end);
        }
    }
    if (arcs.empty()) return 1.0;
    // The caps come sorted by azimuth, so the starts are nearly sorted: insertion sort is ~linear.
    for (size_t i = 1; i < arcs.size(); ++i) {
        const std::pair<double, double> a = arcs[i];
        size_t j = i;
        for (; j > 0 && arcs[j - 1].first > a.first; --j) arcs[j] = arcs[j - 1];
        arcs[j] = a;
    }
    double closed = 0.0, lo = arcs[0].first, hi = arcs[0].second;
    for (size_t k = 1; k < arcs.size(); ++k) {
        if (arcs[k].first > hi) {
            closed += hi - lo;
            lo = arcs[k].first;
        }
        hi = std::max(hi, arcs[k].second);
    }
    closed += hi - lo;
    return std::clamp(1.0 - closed / kTwoPi, 0.0, 1.0);
}

// The ring angle of parameter u in [0, 1], in which the region's measure is uniform: u = sin^2 t /
// sin^2 t_max (cosine) or (1 - cos t) / (1 - cos t_max) (solid angle).
struct RingMap {
    CapMeasure measure;
    double scale;  // sin^2 t_max, or 1 - cos t_max = 2 sin^2(t_max / 2) (exact for tiny suns)
    void at(double u, double& cos_t, double& sin_t) const {
        ring_angle(measure, scale, u, cos_t, sin_t);
    }
};

struct Cell {
    double u0, u1;
    uint32_t beta0, beta1;  // offsets of the endpoint betas in the pool
    double lo, hi;          // bracket of the open share on the cell
    double error() const { return 0.5 * (hi - lo) * (u1 - u0); }
    bool operator<(const Cell& o) const { return error() < o.error(); }
};

}  // namespace

bool sphere_cap(const Vec3& p, const Vec3& c, double r, double reach, DirectionCap& cap,
                bool& inside) {
    inside = false;
    const Vec3 v = c - p;
    const double d = glm::length(v);
    if (!(r > 0.0) || !std::isfinite(d)) return false;
    const double gap = d - r;
    constexpr double kOnSurface = 1e-9;  // relative: a hit point's rounding is ~1e-15
    if (gap < -kOnSurface * r) {
        inside = true;
        return true;
    }
    if (!(d > 0.0) || gap >= reach) return false;
    cap.axis = v / d;
    if (gap <= kOnSurface * r) {
        // On the surface every direction into the sphere hits it at once: a half space.
        cap.cos_half = 0.0;
        cap.sin_half = 1.0;
        return true;
    }
    const double tangent2 = gap * (d + r);  // d^2 - r^2 without cancellation
    if (!(reach < kInf) || reach * reach >= tangent2) {
        cap.sin_half = r / d;
        cap.cos_half = std::sqrt(tangent2) / d;
    } else {
        // Only hits nearer than `reach`: the near hit distance grows away from the axis, so they
        // form the smaller cap whose rim rays meet the sphere at distance `reach`.
        cap.cos_half = std::min(1.0, (reach * reach + tangent2) / (2.0 * reach * d));
        cap.sin_half = std::sqrt(std::max(0.0, (1.0 - cap.cos_half) * (1.0 + cap.cos_half)));
    }
    return true;
}

OpenShare open_share(const Vec3& axis, double theta_max, CapMeasure measure,
                     const std::vector<DirectionCap>& caps, double tolerance, CapScratch& scratch) {
    OpenShare out;
    const double cos_max = std::cos(theta_max), sin_max = std::sin(theta_max);
    // A frame about the axis for the azimuths.
    const Vec3 helper = std::abs(axis.x) < 0.6 ? Vec3(1.0, 0.0, 0.0) : Vec3(0.0, 1.0, 0.0);
    const Vec3 t = glm::normalize(glm::cross(helper, axis));
    const Vec3 b = glm::cross(axis, t);
    std::vector<RingCap>& rc = scratch.caps;
    rc.clear();
    for (const DirectionCap& c : caps) {
        const double cos_c = glm::dot(c.axis, axis);
        const double sin_c = glm::length(glm::cross(c.axis, axis));
        // Misses the region: the angle to the axis is at least theta_max + half angle.
        const double cos_sum = cos_max * c.cos_half - sin_max * c.sin_half;
        const bool sum_below_pi = sin_max * c.cos_half + cos_max * c.sin_half > 0.0;
        if (sum_below_pi && cos_c <= cos_sum) continue;
        // Covers the region: angle + theta_max <= half angle.
        if (cos_c * cos_max - sin_c * sin_max >= c.cos_half &&
            sin_c * cos_max + cos_c * sin_max >= 0.0) {
            out.value = 0.0;
            return out;
        }
        double phi = std::atan2(glm::dot(c.axis, b), glm::dot(c.axis, t));
        if (phi < 0.0) phi += 2.0 * kPi;
        const double peak = c.cos_half > 0.0 ? cos_c / c.cos_half : 2.0;
        rc.push_back(RingCap{phi, cos_c, sin_c, c.cos_half, peak});
    }
    if (rc.empty()) return out;
    std::sort(rc.begin(), rc.end(),
              [](const RingCap& a, const RingCap& b) { return a.phi < b.phi; });

    const size_t k = rc.size();
    const RingMap map{measure, measure == CapMeasure::Cosine
                                   ? sin_max * sin_max
                                   : 2.0 * std::pow(std::sin(0.5 * theta_max), 2)};
    std::vector<double>& pool = scratch.beta_a;
    pool.clear();
    auto betas_at = [&](double u) {
        double cos_t, sin_t;
        map.at(u, cos_t, sin_t);
        const uint32_t offset = uint32_t(pool.size());
        for (const RingCap& c : rc) pool.push_back(arc_half_width(c, cos_t, sin_t));
        return offset;
    };
    std::vector<double>& lo_beta = scratch.beta_lo;
    std::vector<double>& hi_beta = scratch.beta_hi;
    lo_beta.resize(k);
    hi_beta.resize(k);
    auto bracket = [&](Cell& cell) {
        double cos0, sin0, cos1, sin1;
        map.at(cell.u0, cos0, sin0);
        map.at(cell.u1, cos1, sin1);
        for (size_t i = 0; i < k; ++i) {
            const double a = pool[cell.beta0 + i], z = pool[cell.beta1 + i];
            lo_beta[i] = std::min(a, z);
            hi_beta[i] = std::max(a, z);
            // beta rises to one maximum where cos t = cos c / cos a, then falls.
            const double pc = rc[i].peak_cos;
            if (pc < cos0 && pc > cos1)
                hi_beta[i] = std::max(
                    hi_beta[i], arc_half_width(rc[i], pc, std::sqrt(std::max(0.0, 1.0 - pc * pc))));
        }
        cell.lo = ring_open(rc, hi_beta.data(), scratch.arcs);
        cell.hi = ring_open(rc, lo_beta.data(), scratch.arcs);
        ++out.cells;
    };

    // Refine the cell of largest error bound until the bound's total is within the tolerance.
    constexpr uint32_t kMaxCells = 1u << 16;
    std::priority_queue<Cell> heap;
    double value = 0.0;
    Cell root{0.0, 1.0, betas_at(0.0), betas_at(1.0), 0.0, 1.0};
    bracket(root);
    double total = root.error();
    heap.push(root);
    const size_t max_pool = size_t(1) << 22;  // 32 MB of arc widths at most
    while (total > tolerance && out.cells + 2 <= kMaxCells && pool.size() + k <= max_pool &&
           !heap.empty()) {
        const Cell cell = heap.top();
        heap.pop();
        total -= cell.error();
        const double mid = 0.5 * (cell.u0 + cell.u1);
        if (!(mid > cell.u0 && mid < cell.u1)) {  // cannot split further: keep its bound
            out.bound += cell.error();
            value += 0.5 * (cell.lo + cell.hi) * (cell.u1 - cell.u0);
            continue;
        }
        const uint32_t beta_mid = betas_at(mid);
        Cell left{cell.u0, mid, cell.beta0, beta_mid, 0.0, 1.0};
        Cell right{mid, cell.u1, beta_mid, cell.beta1, 0.0, 1.0};
        bracket(left);
        bracket(right);
        for (const Cell& c : {left, right}) {
            total += c.error();
            heap.push(c);
        }
    }
    while (!heap.empty()) {
        const Cell& c = heap.top();
        value += 0.5 * (c.lo + c.hi) * (c.u1 - c.u0);
        out.bound += c.error();
        heap.pop();
    }
    out.value = std::clamp(value, 0.0, 1.0);
    return out;
}

void ring_angle(CapMeasure measure, double scale, double u, double& cos_t, double& sin_t) {
    if (measure == CapMeasure::Cosine) {
        const double s2 = std::clamp(u * scale, 0.0, 1.0);
        sin_t = std::sqrt(s2);
        cos_t = std::sqrt(1.0 - s2);
    } else {
        const double one_minus = u * scale;
        cos_t = 1.0 - one_minus;
        sin_t = std::sqrt(std::max(0.0, one_minus * (2.0 - one_minus)));
    }
}

}  // namespace vr
