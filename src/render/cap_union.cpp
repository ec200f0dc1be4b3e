#include "render/cap_union.h"

#include <algorithm>
#include <bit>
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

// The open share of a ring whose n caps close the arcs phi_i +- beta_i.
double ring_open(const double* phi, const double* beta, size_t n,
                 std::vector<std::pair<double, double>>& arcs) {
    constexpr double kTwoPi = 2.0 * kPi;
    arcs.clear();
    for (size_t i = 0; i < n; ++i) {
        if (!(beta[i] > 0.0)) continue;
        if (beta[i] >= kPi) return 0.0;
        double start = phi[i] - beta[i];  // phi in [0, 2 pi): start in [-pi, 2 pi)
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
    // The parameter of the ring at angle t in [0, t_max] (the inverse of `at`).
    double u_of(double t) const {
        if (measure == CapMeasure::Cosine) return std::pow(std::sin(t), 2) / scale;
        return 2.0 * std::pow(std::sin(0.5 * t), 2) / scale;
    }
};

// A theta cell: the rings [u0, u1], and its caps, the entries [first, first + count) of the
// scratch's entry arrays (the caps whose rings meet the cell; the others close nothing on it).
struct Cell {
    double u0, u1;
    uint32_t first, count;
    double lo, hi;  // bracket of the open share on the cell
    double error() const { return 0.5 * (hi - lo) * (u1 - u0); }
    bool operator<(const Cell& o) const { return error() < o.error(); }
};

// The caps that meet the region, in the frame of its axis, sorted by azimuth, each with the rings
// it meets; false when one covers the whole region.
bool ring_caps(const Vec3& axis, double theta_max, const RingMap& map,
               const std::vector<DirectionCap>& caps, std::vector<RingCap>& rc) {
    const double cos_max = std::cos(theta_max), sin_max = std::sin(theta_max);
    Vec3 t, b;
    axis_frame(axis, t, b);
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
            sin_c * cos_max + cos_c * sin_max >= 0.0)
            return false;
        double phi = std::atan2(glm::dot(c.axis, b), glm::dot(c.axis, t));
        if (phi < 0.0) phi += 2.0 * kPi;
        const double peak = c.cos_half > 0.0 ? cos_c / c.cos_half : 2.0;
        // The rings it meets: polar angles within its half-angle of its axis's, widened by far
        // more than their rounding so that a cap left out of a cell surely closes nothing on it.
        constexpr double kRingMargin = 1e-9;
        const double theta = std::atan2(sin_c, cos_c);
        const double a = std::acos(std::clamp(c.cos_half, -1.0, 1.0));
        const double t0 = theta - a - kRingMargin, t1 = theta + a + kRingMargin;
        const double u_lo = t0 <= 0.0 ? 0.0 : (t0 >= theta_max ? 1.0 : map.u_of(t0));
        const double u_hi = t1 >= theta_max ? 1.0 : map.u_of(t1);
        rc.push_back(RingCap{phi, cos_c, sin_c, c.cos_half, peak, u_lo, u_hi});
    }
    std::sort(rc.begin(), rc.end(),
              [](const RingCap& a, const RingCap& b) { return a.phi < b.phi; });
    return true;
}

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

namespace {

// Margin (radians) on every angle the grid compares: far above the rounding of unit vectors and
// of atan2 and asin (~1e-15), far below a cell (1.4 degrees or less).
constexpr double kGridMargin = 1e-9;

// cos and sin of the middle azimuth of each of the 64 sectors.
struct SectorTable {
    double cos_mid[CoveredCells::kSectors], sin_mid[CoveredCells::kSectors];
    SectorTable() {
        for (int j = 0; j < CoveredCells::kSectors; ++j) {
            const double phi = 2.0 * kPi * (j + 0.5) / CoveredCells::kSectors;
            cos_mid[j] = std::cos(phi);
            sin_mid[j] = std::sin(phi);
        }
    }
};
const SectorTable kSectorTable;

}  // namespace

void CoveredCells::reset(const Vec3& axis, double theta_max) {
    axis_ = axis;
    axis_frame(axis, tx_, ty_);
    std::fill(std::begin(marked_), std::end(marked_), uint64_t(0));
    full_rings_ = 0;
    const double dtheta = theta_max / kRings;
    if (dtheta == dtheta_) return;  // the ring tables of the last region (the sky's, say)
    dtheta_ = dtheta;
    for (int i = 0; i < kRings; ++i) {
        const double mid = (i + 0.5) * dtheta;
        // A cell's points lie within dtheta / 2 of its middle ring along a meridian, and within
        // sin(theta_hi) * dphi / 2 of that meridian along their ring (an arc, longer than the
        // great-circle angle): the cell lies in a circle of that sum about its middle.
        const double rho =
            0.5 * dtheta + std::sin((i + 1) * dtheta) * (kPi / kSectors) + kGridMargin;
        cos_mid_[i] = std::cos(mid);
        sin_mid_[i] = std::sin(mid);
        cos_rho_[i] = std::cos(rho);
        sin_rho_[i] = std::sin(rho);
    }
}

CoveredCells::Span CoveredCells::span_of(const DirectionCap& cap) const {
    Span span;
    span.local = Vec3(glm::dot(cap.axis, tx_), glm::dot(cap.axis, ty_), glm::dot(cap.axis, axis_));
    const double sin_c = std::hypot(span.local.x, span.local.y);
    const double theta = std::atan2(sin_c, span.local.z);
    const double alpha = std::atan2(cap.sin_half, cap.cos_half);
    const double lo = theta - alpha - kGridMargin, hi = theta + alpha + kGridMargin;
    if (lo >= kRings * dtheta_) return span;  // misses the region
    span.ring0 = std::max(0, int(std::floor(lo / dtheta_)));
    span.ring1 = std::min(kRings - 1, int(std::floor(hi / dtheta_)));
    if (lo <= 0.0 || hi >= kPi) {  // holds the axis or its opposite: every azimuth
        span.sectors = ~uint64_t(0);
        return span;
    }
    // Seen from the axis the cap spans the azimuths within asin(sin alpha / sin theta) of its own.
    const double half = std::asin(std::min(1.0, cap.sin_half / sin_c)) + kGridMargin;
    double phi = std::atan2(span.local.y, span.local.x);
    if (phi < 0.0) phi += 2.0 * kPi;
    const double dphi = 2.0 * kPi / kSectors;
    const int first = int(std::floor((phi - half) / dphi)),
              last = int(std::floor((phi + half) / dphi));
    const int count = last - first + 1;
    if (count >= kSectors) {
        span.sectors = ~uint64_t(0);
        return span;
    }
    const uint64_t run = (uint64_t(1) << count) - 1;
    const int shift = ((first % kSectors) + kSectors) % kSectors;
    span.sectors = shift == 0 ? run : (run << shift) | (run >> (kSectors - shift));
    return span;
}

bool CoveredCells::covers(const DirectionCap& cap) const { return full() || covers(span_of(cap)); }

bool CoveredCells::covers(const Span& span) const {
    for (int i = span.ring0; i <= span.ring1; ++i)
        if ((marked_[i] & span.sectors) != span.sectors) return false;
    return true;
}

void CoveredCells::mark(const DirectionCap& cap) { mark(cap, span_of(cap)); }

bool CoveredCells::add(const DirectionCap& cap) {
    if (full()) return false;
    const Span span = span_of(cap);
    if (covers(span)) return false;
    mark(cap, span);
    return true;
}

void CoveredCells::mark(const DirectionCap& cap, const Span& span) {
    for (int i = span.ring0; i <= span.ring1; ++i) {
        uint64_t open = span.sectors & ~marked_[i];
        if (open == 0) continue;
        // The cap holds a cell's circle when the angle between their centres is at most
        // alpha - rho: cos(angle) >= cos(alpha - rho), with alpha - rho kept clear of 0, where
        // a cosine's rounding would blur the angle.
        const double sin_diff = cap.sin_half * cos_rho_[i] - cap.cos_half * sin_rho_[i];
        if (!(sin_diff > 1e-6)) continue;
        const double threshold = cap.cos_half * cos_rho_[i] + cap.sin_half * sin_rho_[i];
        const Vec3& a = span.local;
        const double z = a.z * cos_mid_[i];
        while (open != 0) {
            const int j = std::countr_zero(open);
            open &= open - 1;
            const double d =
                sin_mid_[i] * (a.x * kSectorTable.cos_mid[j] + a.y * kSectorTable.sin_mid[j]) + z;
            if (d >= threshold) marked_[i] |= uint64_t(1) << j;
        }
        if (marked_[i] == ~uint64_t(0)) ++full_rings_;
    }
}

OpenShare open_share(const Vec3& axis, double theta_max, CapMeasure measure,
                     const std::vector<DirectionCap>& caps, double tolerance, CapScratch& scratch) {
    OpenShare out;
    const double sin_max = std::sin(theta_max);
    const RingMap map{measure, measure == CapMeasure::Cosine
                                   ? sin_max * sin_max
                                   : 2.0 * std::pow(std::sin(0.5 * theta_max), 2)};
    std::vector<RingCap>& rc = scratch.caps;
    if (!ring_caps(axis, theta_max, map, caps, rc)) {
        out.value = 0.0;
        return out;
    }
    if (rc.empty()) return out;
    std::vector<uint32_t>& entry_cap = scratch.entry_cap;
    std::vector<double>&beta0 = scratch.entry_beta0, &beta1 = scratch.entry_beta1;
    entry_cap.clear();
    beta0.clear();
    beta1.clear();
    auto beta_at = [&](const RingCap& c, double u) {
        double cos_t, sin_t;
        map.at(u, cos_t, sin_t);
        return arc_half_width(c, cos_t, sin_t);
    };
    std::vector<double>& phi = scratch.phi;
    std::vector<double>& lo_beta = scratch.beta_lo;
    std::vector<double>& hi_beta = scratch.beta_hi;
    auto bracket = [&](Cell& cell) {
        double cos0, sin0, cos1, sin1;
        map.at(cell.u0, cos0, sin0);
        map.at(cell.u1, cos1, sin1);
        phi.resize(cell.count);
        lo_beta.resize(cell.count);
        hi_beta.resize(cell.count);
        for (uint32_t k = 0; k < cell.count; ++k) {
            const uint32_t e = cell.first + k;
            const RingCap& c = rc[entry_cap[e]];
            const double a = beta0[e], z = beta1[e];
            phi[k] = c.phi;
            lo_beta[k] = std::min(a, z);
            hi_beta[k] = std::max(a, z);
            // beta rises to one maximum where cos t = cos c / cos a, then falls.
            const double pc = c.peak_cos;
            if (pc < cos0 && pc > cos1)
                hi_beta[k] = std::max(
                    hi_beta[k], arc_half_width(c, pc, std::sqrt(std::max(0.0, 1.0 - pc * pc))));
        }
        cell.lo = ring_open(phi.data(), hi_beta.data(), cell.count, scratch.arcs);
        cell.hi = ring_open(phi.data(), lo_beta.data(), cell.count, scratch.arcs);
        ++out.cells;
    };

    Cell root{0.0, 1.0, 0, uint32_t(rc.size()), 0.0, 1.0};
    for (uint32_t i = 0; i < rc.size(); ++i) {
        entry_cap.push_back(i);
        beta0.push_back(beta_at(rc[i], 0.0));
        beta1.push_back(beta_at(rc[i], 1.0));
    }
    bracket(root);

    // Refine the cell of largest error bound until the bound's total is within the tolerance.
    constexpr uint32_t kMaxCells = 1u << 16;
    const size_t max_entries = size_t(1) << 22;  // 20 bytes each: 80 MB at most
    std::priority_queue<Cell> heap;
    double value = 0.0;
    double total = root.error();
    heap.push(root);
    std::vector<double>& beta_mid = scratch.beta_mid;
    while (total > tolerance && out.cells + 2 <= kMaxCells && !heap.empty() &&
           entry_cap.size() + 2 * size_t(heap.top().count) <= max_entries) {
        const Cell cell = heap.top();
        heap.pop();
        total -= cell.error();
        const double mid = 0.5 * (cell.u0 + cell.u1);
        if (!(mid > cell.u0 && mid < cell.u1)) {  // cannot split further: keep its bound
            out.bound += cell.error();
            value += 0.5 * (cell.lo + cell.hi) * (cell.u1 - cell.u0);
            continue;
        }
        beta_mid.resize(cell.count);
        for (uint32_t k = 0; k < cell.count; ++k)
            beta_mid[k] = beta_at(rc[entry_cap[cell.first + k]], mid);
        // Each half keeps the cell's caps that meet its rings, with their arcs at its ends.
        auto half = [&](double u0, double u1, bool left) {
            Cell c{u0, u1, uint32_t(entry_cap.size()), 0, 0.0, 1.0};
            for (uint32_t k = 0; k < cell.count; ++k) {
                const uint32_t e = cell.first + k;
                const RingCap& rcap = rc[entry_cap[e]];
                if (rcap.u_hi < u0 || rcap.u_lo > u1) continue;
                entry_cap.push_back(entry_cap[e]);
                beta0.push_back(left ? beta0[e] : beta_mid[k]);
                beta1.push_back(left ? beta_mid[k] : beta1[e]);
                ++c.count;
            }
            bracket(c);
            total += c.error();
            heap.push(c);
        };
        half(cell.u0, mid, true);
        half(mid, cell.u1, false);
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

namespace soft_light_detail {
const TurnTable kTurns = [] {
    TurnTable t;
    for (int k = 0; k <= 256; ++k) {
        t.cos[k] = std::cos(2.0 * kPi * k / 256.0);
        t.sin[k] = std::sin(2.0 * kPi * k / 256.0);
    }
    return t;
}();
}  // namespace soft_light_detail

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
