// Sky light A(p) and area-light visibility V_l (docs/rendering.md, Soft light with error bounds) at
// a shading point, to the absolute error --light-tolerance.
//
// Fast path (hard bound): in a scene whose only primitives are opaque spheres, with no gas, the
// closed part of a region of directions is exactly a union of spherical caps (one per sphere; an
// --ao-distance or a light's distance trims a cap to a smaller cap), integrated by open_share()
// with a deterministic bound. The spheres are gathered nearest first; a cap (or a hierarchy
// node's) that lies in directions one nearer cap already closes is dropped (CoveredCells), which
// leaves the union as it was. A point whose gathering would test more balls than twice the
// rays a plain Monte Carlo estimate needs at the worst variance, (t_99 / 2E)^2, is sampled
// instead (a crowd of far atoms at a loose tolerance): there, rays cost less than caps, and
// surely converge. Everything else (meshes, boxes, see-through surfaces, gas as an
// attenuator, an occluder straddling a sphere light) takes the sampling path: shadow rays along
// one scrambled (0,2)-sequence per point (render/sobol.h), read as R = 8 replicas of 2^k points
// each (k = 1 .. 14), stopping once the Student-t 99% interval of the replicas' means is within
// the tolerance and there have been rays enough (ln(100) / tolerance) to hit, at 99%, any share of
// the cone as large as the tolerance. The estimate is the mean of all 8 replicas, which together
// are stratified as finely as their rays allow; their spread overstates its error.
// That bound is a confidence level, not a certainty; where 8 x 128^2 rays do not reach it the
// point is counted (SoftLightCounts::unconverged).
#pragma once
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/ray.h"
#include "render/accel.h"
#include "render/cap_union.h"
#include "render/flat_scene.h"
#include "render/gas.h"
#include "render/options.h"
#include "render/sky_map.h"

namespace vr {

// The share of --light-tolerance a lattice point of the sky light's sharing is estimated to
// (render/sky_share.h): its cost grows as the inverse square, and the rest is the interpolation's.
inline constexpr double kSharedNodeShare = 0.75;

// The sampling path's rays at a point, at most: 8 blocks of 128 x 128 directions.
inline constexpr uint64_t kSoftLightMaxRays = 8 * 128 * 128;

struct SoftLightCounts {
    uint64_t exact_points = 0;    // fast path: evaluations with a hard bound
    uint64_t sampled_points = 0;  // sampling path
    uint64_t unconverged = 0;     // sampling path stopped at its cap above the tolerance
    uint64_t rays = 0;            // sampling path shadow rays
    uint64_t shared_points = 0;   // sky light interpolated between lattice points (sky_share.h)
    void add(const SoftLightCounts& o) {
        shared_points += o.shared_points;
        exact_points += o.exact_points;
        sampled_points += o.sampled_points;
        unconverged += o.unconverged;
        rays += o.rays;
    }
};

// The opaque spheres of a scene under a bounding-sphere hierarchy, for gathering the spheres that
// can close part of a cone of directions from a point.
class SphereOccluders {
  public:
    void build(const std::vector<Sphere>& spheres);
    // Visits the spheres that may meet the cone of half-angle (cos, sin) about unit `axis` from
    // `p` nearer than `reach`, nearest surface first, so that near spheres, whose caps are large,
    // come before the far ones they hide. `pass(centre, radius)`: whether a node's bounding ball
    // (and so every sphere in it) may be passed over; `visit(i)` returns false to stop.
    template <class Pass, class Visit>
    void visit_nearest(const Vec3& p, const Vec3& axis, double cos_half, double sin_half,
                       double reach, Pass&& pass, Visit&& visit) const;
    const Vec3& center(uint32_t i) const { return centers_[i]; }
    double radius(uint32_t i) const { return radii_[i]; }

  private:
    struct Node {
        Vec3 center;
        double radius;
        uint32_t first, count;  // leaf: spheres [first, first + count); inner: count = 0
        uint32_t right;         // inner: the second child (the first is the next node)
    };
    uint32_t build_node(uint32_t first, uint32_t count);
    static bool cone_meets_ball(const Vec3& p, const Vec3& axis, double cos_a, double sin_a,
                                const Vec3& c, double r);
    std::vector<Node> nodes_;
    std::vector<Vec3> centers_;
    std::vector<double> radii_;
};

template <class Pass, class Visit>
void SphereOccluders::visit_nearest(const Vec3& p, const Vec3& axis, double cos_half,
                                    double sin_half, double reach, Pass&& pass,
                                    Visit&& visit) const {
    struct Entry {
        double near;     // distance from p to the ball's surface (negative inside)
        uint32_t index;  // a node, or a sphere
        bool sphere;
        bool operator<(const Entry& o) const { return near > o.near; }  // nearest on top
    };
    thread_local std::vector<Entry> heap;
    heap.clear();
    if (nodes_.empty()) return;
    auto push = [&](const Vec3& c, double r, uint32_t index, bool sphere) {
        const double near = glm::length(c - p) - r;
        if (near >= reach || !cone_meets_ball(p, axis, cos_half, sin_half, c, r)) return;
        heap.push_back(Entry{near, index, sphere});
        std::push_heap(heap.begin(), heap.end());
    };
    push(nodes_[0].center, nodes_[0].radius, 0, false);
    while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end());
        const Entry e = heap.back();
        heap.pop_back();
        if (e.sphere) {
            if (!visit(e.index)) return;
            continue;
        }
        const Node& n = nodes_[e.index];
        if (pass(n.center, n.radius)) continue;
        if (n.count > 0) {
            for (uint32_t i = n.first; i < n.first + n.count; ++i)
                push(centers_[i], radii_[i], i, true);
        } else {
            push(nodes_[e.index + 1].center, nodes_[e.index + 1].radius, e.index + 1, false);
            push(nodes_[n.right].center, nodes_[n.right].radius, n.right, false);
        }
    }
}

class SoftLighting {
  public:
    SoftLighting(const FlatScene& scene, const Accel& accel, const GasVolume* gas,
                 const RenderOptions& options);
    bool sky() const { return sky_; }
    // The --sky FILE map, or null (a colour, or no sky light).
    const SkyMap* sky_map() const { return sky_map_.get(); }

    // A(p) at surface point p (rounding bound p_error) with geometric normal ng and shading normal
    // n, both facing the viewer.
    double sky_visibility(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& n,
                          SoftLightCounts& counts) const;
    // Whether the sky light may be shared between neighbouring pixels (render/sky_share.h): a
    // constant sky on the sampling path (the cap path keeps its hard bound at every point).
    bool shares_sky() const { return sky_ && !sky_map_ && !spheres_only_ && gas_ == nullptr; }
    // A(p) at a lattice point of the sharing: to kSharedNodeShare of the tolerance on its own (no
    // pixel's other samples share its budget); the interpolation keeps the rest.
    double shared_sky_visibility(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& n,
                                 SoftLightCounts& counts) const;
    double tolerance() const { return tolerance_; }
    // With a sky map: (1/pi) * integral over the hemisphere about n of V(p, w) L(w) max(n.w, 0) dw
    // per channel, to the absolute error tolerance * (the channel's largest texel): the part up to
    // the smallest texel as A(p) (hard bound where the caps apply), the rest sampled (99%).
    Vec3 sky_radiance(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& n,
                      SoftLightCounts& counts) const;
    // V_l of an area light (source_radius or angular_radius > 0) from p.
    // A zero `ng` is a point in the gas, with no surface.
    double light_visibility(const Light& light, const Vec3& p, const Vec3& p_error, const Vec3& ng,
                            SoftLightCounts& counts) const;

  private:
    // The shadow-ray visibility along unit w from p: to the near side of the sphere light
    // (`target`, `target_radius` > 0), else up to `reach`; 0 below the surface ng. `blocker`:
    // the hint of Accel::transmittance, kept across one point's rays.
    double shadow_visibility(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& w,
                             double reach, const Vec3& target, double target_radius,
                             SoftLightCounts& counts, uint32_t& blocker) const;
    // The open share of the cone by shadow rays (the sampling path). `target_radius` > 0: the rays
    // end on the sphere light of that radius at `target`; else they run `reach` far.
    // `interval`: the 99% interval's half-width at which it stops; `min_rays`: the rays it traces
    // at least.
    double sampled_share(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& axis,
                         double theta_max, CapMeasure measure, double reach, const Vec3& target,
                         double target_radius, uint64_t key, double interval, double min_rays,
                         SoftLightCounts& counts) const;
    // The fast path; false when it does not apply here (an occluder straddles the light).
    bool exact_share(const Vec3& p, const Vec3& axis, double theta_max, CapMeasure measure,
                     double reach, double light_near, bool skip_own, double& share,
                     SoftLightCounts& counts) const;

    const Accel& accel_;
    const GasVolume* gas_;
    double tolerance_;
    // The sampling path per point: its 99% interval's half-width, E sqrt(K), and its least rays,
    // ln(100) / (K E), for the K samples of a pixel of a fixed sampler (1 for the others).
    int pixel_samples_ = 1;
    double point_interval_ = 0.0;
    double min_rays_ = 0.0;
    double ao_distance_;
    uint64_t seed_;
    bool sky_ = false;
    std::shared_ptr<const SkyMap> sky_map_;
    bool spheres_only_ = false;  // the fast path applies
    SphereOccluders occluders_;
};

}  // namespace vr
