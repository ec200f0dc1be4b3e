// Sky light A(p) and area-light visibility V_l (SPEC section 13) at a shading point, to the
// absolute error --light-tolerance.
//
// Fast path (hard bound): in a scene whose only primitives are opaque spheres, with no gas, the
// closed part of a region of directions is exactly a union of spherical caps (one per sphere; an
// --ao-distance or a light's distance trims a cap to a smaller cap), integrated by open_share()
// with a deterministic bound.
//
// Sampling path: shadow rays on R = 8 independently jittered stratified patterns of m x m
// directions (m = 4, 8, ... 128), stopping once the Student-t 99% interval of their mean is within
// the tolerance. That bound is a confidence level, not a certainty; where the 128 x 128 patterns
// do not reach it the point is counted (SoftLightCounts::unconverged).
//
// Mixed scenes (opaque spheres beside meshes, cylinders, see-through surfaces or gas, as a
// ball-and-stick molecule): the opaque spheres' visibility V_s is a union of caps and the rest's
// transmittance T multiplies it, so share = S_caps - D with D = the measure of V_s (1 - T): S_caps
// by the cap integral to E/2 (hard), D by the sampling path to E/2 (99%), where a direction
// inside a cap costs no ray and D's variance is only that of what the other geometry closes in
// the open directions. Where the rest is cylinders, cones, boxes and triangles, balls bound it
// (a few along each cylinder): outside their caps D's integrand is 0 without a ray, and a point
// whose region meets no such cap has D = 0 exactly.
#pragma once
#include <cstdint>
#include <vector>

#include "core/ray.h"
#include "render/accel.h"
#include "render/flat_scene.h"
#include "render/gas.h"
#include "render/options.h"
#include "render/soft_light.h"

namespace vr {

struct SoftLightCounts {
    uint64_t exact_points = 0;    // cap integrals with a hard bound (fast path and mixed scenes)
    uint64_t sampled_points = 0;  // sampling path (alone, or the mixed scenes' correction)
    uint64_t unconverged = 0;     // sampling path stopped at its cap above the tolerance
    uint64_t rays = 0;            // sampling path shadow rays
    uint64_t caps = 0;            // caps integrated, summed over the cap integrals
    void add(const SoftLightCounts& o) {
        caps += o.caps;
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
    // Indices of the spheres that may meet the cone of half-angle (cos, sin) about unit `axis` from
    // `p` nearer than `reach`, appended to `out`.
    void gather(const Vec3& p, const Vec3& axis, double cos_half, double sin_half, double reach,
                std::vector<uint32_t>& out) const;
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
    std::vector<Node> nodes_;
    std::vector<Vec3> centers_;
    std::vector<double> radii_;
};

class SoftLighting {
  public:
    SoftLighting(const FlatScene& scene, const Accel& accel, const GasVolume* gas,
                 const RenderOptions& options);
    bool sky() const { return sky_; }

    // A(p) at surface point p (rounding bound p_error) with geometric normal ng and shading normal
    // n, both facing the viewer.
    double sky_visibility(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& n,
                          SoftLightCounts& counts) const;
    // V_l of an area light (source_radius or angular_radius > 0) from p.
    double light_visibility(const Light& light, const Vec3& p, const Vec3& p_error, const Vec3& ng,
                            SoftLightCounts& counts) const;

  private:
    // The open share of the cone by shadow rays (the sampling path), to `tolerance`.
    // `target_radius` > 0: the rays end on the sphere light of that radius at `target`; else they
    // run `reach` far. With `closed` (mixed scenes) it is D instead: the share closed by the rays
    // but by none of these caps (a direction inside one costs no ray).
    double sampled_share(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& axis,
                         double theta_max, CapMeasure measure, double reach, const Vec3& target,
                         double target_radius, uint64_t key, double tolerance,
                         const std::vector<DirectionCap>* closed,
                         const std::vector<DirectionCap>* maybe, SoftLightCounts& counts) const;
    // The caps of the balls that bound the other geometry in the cone; false when p lies in one.
    bool gather_bounds(const Vec3& p, const Vec3& axis, double theta_max, double reach,
                       const std::vector<DirectionCap>& closed,
                       std::vector<DirectionCap>& caps) const;
    // The caps the opaque spheres close in the cone; false when the cap integral does not apply
    // (an occluder straddles the light; a mixed scene with too many caps to pay), `inside` when p
    // lies in a sphere (all closed).
    bool gather_caps(const Vec3& p, const Vec3& axis, double theta_max, double reach,
                     double light_near, bool skip_own, std::vector<DirectionCap>& caps,
                     bool& inside) const;
    // The share of the cone: by the cap integral alone (spheres only), by sampling alone (no
    // opaque spheres, or the cap integral does not apply) or by both (mixed scenes).
    double share(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& axis,
                 double theta_max, CapMeasure measure, double reach, double light_near,
                 const Vec3& target, double target_radius, uint64_t key,
                 SoftLightCounts& counts) const;

    const Accel& accel_;
    const GasVolume* gas_;
    double tolerance_;
    double ao_distance_;
    uint64_t seed_;
    bool sky_ = false;
    bool spheres_only_ = false;  // the fast path applies
    bool mixed_ = false;         // opaque spheres beside other geometry: caps and sampling
    bool bounded_ = false;       // mixed, and balls bound all the other geometry (`others_`)
    SphereOccluders occluders_;
    SphereOccluders others_;
};

}  // namespace vr
