// Soft light with error bounds (docs/rendering.md, Soft light with error bounds): the share of a
// cone of directions that a union of spherical caps leaves open, integrated with a hard error
// bound.
//
// The region is the set of directions within `theta_max` of an axis (the hemisphere about a normal
// for sky light, a light's cap for an area light), measured either cosine-weighted about the axis
// (sky light: A(p) is the cosine-weighted open share) or by solid angle (an area light's V_l).
// Rings of constant angle theta about the axis meet each cap in one arc centred at the cap's
// azimuth, of half-width beta(theta) known in closed form; the open share of a ring is exact (a
// union of arcs). Over theta the open share f is integrated by bisection: on a cell each beta is
// unimodal in theta (one critical angle, also closed form), so its range on the cell is known, and
// f is bracketed by the rings with every arc at its shortest and at its longest. A cell is accepted
// when its bracket is narrower than twice the tolerance; its estimate is the bracket's middle, so
// every cell's error is at most tolerance times its measure and the total error at most the
// tolerance: a bound that holds for every point, not a confidence level (up to rounding, ~1e-14).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/math.h"

namespace vr {

// A cap of directions: those within `half_angle` of the unit `axis`, stored as cosine and sine.
struct DirectionCap {
    Vec3 axis{0.0, 0.0, 1.0};
    double cos_half = 1.0;
    double sin_half = 0.0;
};

// A right-handed orthonormal frame (tx, ty, axis) about the unit `axis`: the azimuths of the cap
// integral, its cell grid and the sampling path are all measured in it.
inline void axis_frame(const Vec3& axis, Vec3& tx, Vec3& ty) {
    const Vec3 helper = std::abs(axis.x) < 0.6 ? Vec3(1.0, 0.0, 0.0) : Vec3(0.0, 1.0, 0.0);
    tx = glm::normalize(glm::cross(helper, axis));
    ty = glm::cross(axis, tx);
}

// How a region's directions are weighted.
enum class CapMeasure : uint8_t {
    Cosine,      // by cos(theta) about the axis (theta_max is then pi/2: the hemisphere)
    SolidAngle,  // uniform over the solid angle
};

// cos and sin of the polar angle t of parameter u in [0, 1], for a region of `measure` whose
// `scale` is sin^2 t_max (Cosine) or 1 - cos t_max = 2 sin^2(t_max / 2) (SolidAngle: exact for tiny
// suns): u is uniform in the region's measure.
void ring_angle(CapMeasure measure, double scale, double u, double& cos_t, double& sin_t);

// cos and sin of the azimuth 2 pi v for v in [0, 1], to a few ulps: a table of the 257 angles of
// k/256 turns and the Taylor series of what is left (|x| <= pi/256 = 0.0123: the first terms left
// out, x^8/8! and x^9/9!, are below 1e-19), joined by the angle-sum formulas. The sampling path
// turns each shadow ray's v into an azimuth; libm's sincos took 6% of a sky-light render of the S2
// molecule, and with this the render is 4.5% sooner (the same image).
namespace soft_light_detail {
struct TurnTable {
    double cos[257], sin[257];
};
extern const TurnTable kTurns;
}  // namespace soft_light_detail
inline void turn_cos_sin(double v, double& c, double& s) {
    const soft_light_detail::TurnTable& t = soft_light_detail::kTurns;
    const double scaled = v * 256.0;
    const int k = std::clamp(int(scaled + 0.5), 0, 256);
    const double x = (scaled - double(k)) * (2.0 * kPi / 256.0), x2 = x * x;
    const double cx = 1.0 - x2 * (1.0 / 2.0 - x2 * (1.0 / 24.0 - x2 * (1.0 / 720.0)));
    const double sx = x * (1.0 - x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 5040.0))));
    c = t.cos[k] * cx - t.sin[k] * sx;
    s = t.sin[k] * cx + t.cos[k] * sx;
}

struct OpenShare {
    double value = 1.0;  // the open share of the region's measure, in [0, 1]
    double bound = 0.0;  // |value - exact| <= bound (<= the tolerance unless `cells` hit the cap)
    uint32_t cells = 0;  // theta cells evaluated
};

// Per-thread work space, so that integrating allocates nothing once warm.
struct CapScratch {
    struct RingCap {
        double phi, cos_c, sin_c, cos_a;
        double peak_cos;    // cos of the angle of widest arc, or 2 when beta is monotone
        double u_lo, u_hi;  // the rings it meets, in the region's parameter u
    };
    std::vector<RingCap> caps;
    // Per cell entry: the cap, and its arc's half-width on the cell's first and last ring.
    std::vector<uint32_t> entry_cap;
    std::vector<double> entry_beta0, entry_beta1;
    std::vector<double> beta_mid, phi, beta_lo, beta_hi;
    std::vector<std::pair<double, double>> arcs;
};

// The open share of the region within `theta_max` (in (0, pi/2]) of unit `axis`, to the absolute
// `tolerance`, with `caps` closed. Caps that miss the region cost one test each.
OpenShare open_share(const Vec3& axis, double theta_max, CapMeasure measure,
                     const std::vector<DirectionCap>& caps, double tolerance, CapScratch& scratch);

// Directions of a region certainly closed by caps, on a grid of cells about its axis (kRings
// rings of equal theta x 64 sectors of phi; a ring's marks are one 64-bit word). A cell is marked
// when one cap alone holds its bounding circle. A cap whose part in the region meets marked cells
// only closes nothing the marked caps do not, so dropping it leaves the union of caps, and with it
// the open share and its bound, exactly as they were: the cull is conservative, and cells covered
// only by several caps together just stay unmarked.
class CoveredCells {
  public:
    static constexpr int kRings = 64, kSectors = 64;
    static_assert(kSectors == 64, "a ring's sectors are the bits of one uint64_t");
    void reset(const Vec3& axis, double theta_max);
    // Whether every cell that `cap` meets within the region is marked (true for a cap that misses
    // the region).
    bool covers(const DirectionCap& cap) const;
    // Marks the cells that `cap` holds whole.
    void mark(const DirectionCap& cap);
    // covers() and mark() in one: false (and nothing marked) when `cap` adds nothing.
    bool add(const DirectionCap& cap);
    // Every cell is marked: the whole region is closed.
    bool full() const { return full_rings_ == kRings; }

  private:
    struct Span {
        int ring0 = 0, ring1 = -1;  // rings [ring0, ring1]; empty when ring1 < ring0
        uint64_t sectors = 0;       // the sectors it may meet (the same on each of its rings)
        Vec3 local;                 // the cap's axis in the region's frame (z: the region's axis)
    };
    Span span_of(const DirectionCap& cap) const;
    bool covers(const Span& span) const;
    void mark(const DirectionCap& cap, const Span& span);
    Vec3 axis_, tx_, ty_;
    double dtheta_ = 0.0;
    uint64_t marked_[kRings] = {};
    int full_rings_ = 0;
    // Per ring: cos and sin of its middle angle and of its cells' bounding radius.
    double cos_mid_[kRings], sin_mid_[kRings], cos_rho_[kRings], sin_rho_[kRings];
};

// The cap a sphere (centre `c`, radius `r`) closes seen from `p`, counting only hits nearer than
// `reach` (kInf: all): false when it closes nothing. `inside` is set when p lies inside the
// sphere (every direction is closed). A point on the surface (to 1e-9 of the radius) sees a half
// space closed, so that a point on an overlapping sphere's surface is not counted as inside.
bool sphere_cap(const Vec3& p, const Vec3& c, double r, double reach, DirectionCap& cap,
                bool& inside);

}  // namespace vr
