#include "render/sky_area_light.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <string>

#include "render/sampling.h"
#include "render/sobol.h"

namespace vr {
namespace {

constexpr uint32_t kLeafSize = 4;

uint64_t bits_of(double v) {
    uint64_t u;
    std::memcpy(&u, &v, sizeof u);
    return u;
}

// A key for the sampling path's random numbers from the point (and light): the same for every
// thread and tile order.
uint64_t point_key(uint64_t seed, const Vec3& p, const Vec3& q) {
    uint64_t h = seed;
    for (double v : {p.x, p.y, p.z, q.x, q.y, q.z}) h = sample_hash(h, 0, 0, bits_of(v));
    return h;
}

// The t interval sees only what some ray has hit: a closed (or open) share q of the cone that every
// ray misses leaves all replicas equal and the interval 0 wide, however large q. n stratified
// directions miss a share q with probability at most exp(-n q) (each cell's jitter on its own), so
// n >= ln(100) / tolerance rays hit any share as large as the tolerance at 99%, the interval's own
// confidence. Rounded up to a round's rays (8 or 12 x 2^k): 16 at 3e-1, 24 at 2e-1, 48 at 1e-1,
// 6,144 at 1e-3.
double min_samples_to_see(double tolerance) { return std::log(100.0) / tolerance; }

// Two-sided 99% quantiles of Student's t, 7 and 11 dof (the spread of 8 and of 12 replicas).
constexpr double kStudent99 = 3.4995, kStudent99Of11 = 3.1058;

// Removes the caps that lie inside one of the largest caps (atoms behind a near neighbour): they
// close nothing more, and the cap integral's work grows with the number of caps.
void drop_contained(std::vector<DirectionCap>& caps) {
    if (caps.size() < 2) return;
    std::sort(caps.begin(), caps.end(),
              [](const DirectionCap& a, const DirectionCap& b) { return a.cos_half < b.cos_half; });
    constexpr size_t kLargest = 16;
    size_t kept = 1;
    for (size_t i = 1; i < caps.size(); ++i) {
        const DirectionCap& c = caps[i];
        bool inside = false;
        for (size_t j = 0; j < std::min(kept, kLargest) && !inside; ++j) {
            const DirectionCap& big = caps[j];
            // angle(c, big) + a_c <= a_big, with a_big >= a_c: cos(angle) >= cos(a_big - a_c).
            inside =
                glm::dot(c.axis, big.axis) >= big.cos_half * c.cos_half + big.sin_half * c.sin_half;
        }
        if (!inside) caps[kept++] = c;
    }
    caps.resize(kept);
}

}  // namespace

void SphereOccluders::build(const std::vector<Sphere>& spheres) {
    centers_.clear();
    radii_.clear();
    for (const Sphere& s : spheres) {
        if (s.gas || !(s.radius > 0.0)) continue;
        centers_.push_back(s.center);
        radii_.push_back(s.radius);
    }
    nodes_.clear();
    if (!centers_.empty()) build_node(0, uint32_t(centers_.size()));
}

uint32_t SphereOccluders::build_node(uint32_t first, uint32_t count) {
    Bounds3 box;
    for (uint32_t i = first; i < first + count; ++i) box.extend(centers_[i]);
    const Vec3 mid = 0.5 * (box.lo + box.hi);
    double radius = 0.0;
    for (uint32_t i = first; i < first + count; ++i)
        radius = std::max(radius, glm::length(centers_[i] - mid) + radii_[i]);
    const uint32_t index = uint32_t(nodes_.size());
    nodes_.push_back(Node{mid, radius, first, count, 0});
    if (count <= kLeafSize) return index;
    const Vec3 extent = box.hi - box.lo;
    const int axis =
        extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    // Median split: sort the range's spheres (centres and radii together) along the axis.
    std::vector<uint32_t> order(count);
    std::iota(order.begin(), order.end(), first);
    const uint32_t half = count / 2;
    std::nth_element(order.begin(), order.begin() + half, order.end(),
                     [&](uint32_t a, uint32_t b) { return centers_[a][axis] < centers_[b][axis]; });
    std::vector<Vec3> c(count);
    std::vector<double> r(count);
    for (uint32_t k = 0; k < count; ++k) {
        c[k] = centers_[order[k]];
        r[k] = radii_[order[k]];
    }
    std::copy(c.begin(), c.end(), centers_.begin() + first);
    std::copy(r.begin(), r.end(), radii_.begin() + first);
    nodes_[index].count = 0;
    build_node(first, half);
    const uint32_t right = build_node(first + half, count - half);
    nodes_[index].right = right;
    return index;
}

// Whether the cone about `axis` of half-angle (cos_a, sin_a) and the ball (c, r) seen from p can
// share a direction: the angle to the ball's centre is below the sum of the half-angles.
bool SphereOccluders::cone_meets_ball(const Vec3& p, const Vec3& axis, double cos_a, double sin_a,
                                      const Vec3& c, double r) {
    const Vec3 v = c - p;
    const double d = glm::length(v);
    if (!(d > r)) return true;  // p inside the ball
    const double sin_b = r / d, cos_b = std::sqrt((d - r) * (d + r)) / d;
    const double sin_sum = sin_a * cos_b + cos_a * sin_b;
    if (!(sin_sum > 0.0)) return true;  // the half-angles sum to pi: every direction
    const double cos_sum = cos_a * cos_b - sin_a * sin_b;
    return glm::dot(v, axis) > cos_sum * d;
}

SoftLighting::SoftLighting(const FlatScene& scene, const Accel& accel, const GasVolume* gas,
                           const RenderOptions& options)
    : accel_(accel),
      gas_(gas && !gas->empty() ? gas : nullptr),
      tolerance_(options.light_tolerance),
      ao_distance_(options.ao_distance),
      seed_(options.seed),
      sky_(options.sky.has_value() || options.sky_map),
      sky_map_(options.sky_map) {
    // The pixel's samples share the sampling path's error budget (docs/rendering.md, "What
    // --light-tolerance E guarantees"): K box-filtered samples, each point's estimate independent
    // of the others' (its own scrambled sequence), make a pixel mean whose error has 1/sqrt(K) of
    // one point's spread, and whose K n rays together see any share as large as E.
    PixelSampler sampler;
    std::string error;
    if (make_sampler(options, sampler, error))
        pixel_samples_ = std::max(1, sampler.fixed_samples_per_pixel());
    point_interval_ = tolerance_ * std::sqrt(double(pixel_samples_));
    min_rays_ = min_samples_to_see(tolerance_) / double(pixel_samples_);
    // (ClipPlane: the sphere occluders below know no planes; the tracer's clipped queries do.)
    spheres_only_ = scene.quadrics.empty() && scene.meshes.empty() && scene.instances.empty() &&
                    gas_ == nullptr && !scene.any_clip_planes();
    for (const Sphere& s : scene.spheres) {
        if (!spheres_only_) break;
        const uint32_t m =
            s.shading < scene.shadings.size() ? scene.shadings[s.shading].material : 0;
        if (s.gas || (m < scene.materials.size() && scene.materials[m].transparency > 0.0))
            spheres_only_ = false;
    }
    if (spheres_only_) occluders_.build(scene.spheres);
}

bool SoftLighting::exact_share(const Vec3& p, const Vec3& axis, double theta_max,
                               CapMeasure measure, double reach, double light_near, bool skip_own,
                               double& share, SoftLightCounts& counts) const {
    thread_local std::vector<DirectionCap> caps, straddling;
    thread_local CoveredCells covered;
    thread_local CapScratch scratch;
    caps.clear();
    straddling.clear();
    covered.reset(axis, theta_max);
    const bool to_light = light_near >= 0.0;
    const double cos_max = std::cos(theta_max), sin_max = std::sin(theta_max);
    const double cap_reach = to_light ? kInf : reach;
    bool closed = false;  // p lies inside a sphere
    // The gathering gives up (and the point is sampled) once it has tested more balls than twice
    // the rays a plain Monte Carlo estimate would need at the largest variance (1/4) to reach the
    // tolerance at the interval's confidence, (t / 2E)^2: a ball costs less than a ray, and the
    // sampling path, stratified, needs fewer. So only where sampling surely converges, and soon,
    // does a point give up its hard bound: a crowd of thousands of far atoms at a loose tolerance
    // (at 1e-1, 612 tests against 3,600 caps on bench/soft_vs_peers.sh's molecule, where 64 to
    // 256 rays do); at 1e-2 a point gives its caps up only past 61,000 tests, at 1e-3 past 6.1M.
    const double plain_rays = std::pow(kStudent99 / (2.0 * tolerance_), 2);
    const double most_tests = 2.0 * std::max(plain_rays, min_samples_to_see(tolerance_));
    double tests = 0.0;
    bool too_many = false;
    // A node whose bounding ball's cap lies in covered cells holds nothing more to close.
    auto pass = [&](const Vec3& c, double r) {
        if (too_many || ++tests > most_tests) {
            too_many = true;
            return true;
        }
        DirectionCap cap;
        bool inside = false;
        if (!sphere_cap(p, c, r, cap_reach, cap, inside)) return true;
        return !inside && covered.covers(cap);
    };
    auto visit = [&](uint32_t i) {
        if (++tests > most_tests) {
            too_many = true;
            return false;
        }
        const Vec3& c = occluders_.center(i);
        const double r = occluders_.radius(i);
        DirectionCap cap;
        bool inside = false;
        if (!sphere_cap(p, c, r, cap_reach, cap, inside)) return true;
        if (inside) {
            closed = true;
            return false;
        }
        if (to_light) {
            // Only what lies before the light counts; its hits lie between light_near and reach
            // (its centre's distance). An occluder that misses the light's cone is no matter (the
            // sphere under the point, say); one that straddles the light's depth matters only if
            // the nearer caps leave part of it open (checked once they are all known).
            const double cos_sum = cos_max * cap.cos_half - sin_max * cap.sin_half;
            const double sin_sum = sin_max * cap.cos_half + cos_max * cap.sin_half;
            if (sin_sum > 0.0 && glm::dot(cap.axis, axis) <= cos_sum) return true;
            const double d = glm::length(c - p);
            if (d - r >= reach) return true;
            if (d + r > light_near) {
                straddling.push_back(cap);
                return true;
            }
        }
        // The sphere the point lies on closes exactly the half space below its tangent plane.
        if (skip_own && cap.cos_half == 0.0 && glm::dot(cap.axis, axis) < -1.0 + 1e-9) return true;
        if (!covered.add(cap)) return true;  // behind nearer spheres
        caps.push_back(cap);
        return !covered.full();
    };
    occluders_.visit_nearest(p, axis, cos_max, sin_max, reach, pass, visit);
    if (too_many && !closed) return false;
    for (const DirectionCap& cap : straddling)
        if (!closed && !covered.covers(cap)) return false;
    ++counts.exact_points;
    if (closed || covered.full()) {
        share = 0.0;
        return true;
    }
    drop_contained(caps);
    share = open_share(axis, theta_max, measure, caps, tolerance_, scratch).value;
    return true;
}

double SoftLighting::shadow_visibility(const Vec3& p, const Vec3& p_error, const Vec3& ng,
                                       const Vec3& w, double reach, const Vec3& target,
                                       double target_radius, SoftLightCounts& counts,
                                       uint32_t& blocker) const {
    if (!(glm::dot(w, ng) > 0.0)) return 0.0;  // below the surface itself
    Ray ray;
    if (target_radius > 0.0) {
        // To the near side of the sphere light along w (its closest approach if w grazes it).
        const Vec3 v = target - p;
        const double b = glm::dot(w, v);
        const double disc = b * b - (glm::dot(v, v) - target_radius * target_radius);
        const double t = disc > 0.0 ? b - std::sqrt(disc) : b;
        ray = spawn_ray_to(p, p_error, ng, p + t * w);
    } else {
        ray = spawn_ray(p, p_error, ng, w);
        ray.t_max = reach;
    }
    ++counts.rays;
    double v = accel_.transmittance(ray, &blocker);
    if (gas_ && v > 0.0) v *= std::exp(-gas_->optical_depth(ray));
    return std::isfinite(v) ? v : 0.0;
}

namespace {

// A round's new directions: blocks `first` .. `last` - 1 of `block` points, each as (u, v, block),
// in the order they are traced: row by row over one grid of the cone for the whole round (odd rows
// right to left), so that consecutive rays are neighbours and share their blockers (the shadow
// rays' hint). Tracing block after block, as before, put each of a loose tolerance's blocks of 2 or
// 4 points across the whole cone, and the hint spared fewer shadow rays their traversal than in
// round order does (bench/README.md, "Figures behind the comments"). The grid has as many
// boxes as the largest power of 2 not above the round's points (each aligned block of a power-of-2
// count is a net: a box holds 1 or 2).
struct RoundPoint {
    double u, v;
    int block;
    uint32_t box;  // in the round's grid
};
void order_round(const ScrambledSobol2D& sequence, int first, int last, uint32_t block,
                 std::vector<RoundPoint>& points, std::vector<RoundPoint>& ordered,
                 std::vector<uint32_t>& box_start) {
    const uint32_t n = uint32_t(last - first) * block;
    const int grid_bits = 31 - __builtin_clz(n);
    const int nu = 1 << ((grid_bits + 1) / 2), nv = 1 << (grid_bits / 2);
    points.clear();
    box_start.assign(size_t(nu) * size_t(nv) + 1, 0);
    auto box_of = [&](double u, double v) {
        const int row = std::min(int(v * nv), nv - 1), col = std::min(int(u * nu), nu - 1);
        return uint32_t(row * nu + (row % 2 ? nu - 1 - col : col));
    };
    for (int r = first; r < last; ++r)
        sequence.block(uint32_t(r) * block, block, [&](double u, double v) {
            const uint32_t box = box_of(u, v);
            points.push_back({u, v, r, box});
            ++box_start[box + 1];
        });
    for (size_t b = 1; b < box_start.size(); ++b) box_start[b] += box_start[b - 1];
    ordered.resize(points.size());
    for (const RoundPoint& p : points) ordered[box_start[p.box]++] = p;
}

// The mean of f(w) over the cone about `axis` (uniform in its measure) from R replicas, each a
// block of 2^k points of one scrambled (0,2)-sequence (render/sobol.h), in rounds of R = 8 then 12
// blocks of each size, k = 1 .. 14 (16, 24, 32, 48, ... up to 8 x 128 x 128 points), stopping once
// `converged(variance of the replicas' means, Student's t for R - 1 dof)` holds; rounds of fewer
// than `min_samples` directions in all are skipped. Value is double or Vec3 (per channel); `done`
// says whether it converged before the largest blocks.
//
// Each replica is stratified on a grid of 2^k boxes, as a jittered pattern would be, and the first
// 8 x 2^k points on every grid of 8 x 2^k boxes (the next 4 x 2^k on every grid of theirs), which
// eight patterns jittered apart are not: the mean's error is that of one pattern of all the points.
// The replicas are not independent but negatively correlated (they fill each other's gaps), so
// their spread overstates the mean's error: the interval stays conservative.
//
// A round keeps the rays of the last: 12 blocks add 4 after the first 8; then 16 blocks of 2^k
// points are 8 blocks of 2^(k+1). So a round adds 1.5x or 1.33x the rays, and a point stops at
// most that far past the rays it needed (rounds of 8 blocks only, doubling, stopped up to 2x past:
// at 2e-1 a point that 23 rays let see a share of the tolerance traced 32).
template <class Value, class F, class Converged>
Value stratified_mean(const Vec3& axis, double theta_max, CapMeasure measure, uint64_t key,
                      double min_samples, F&& f, Converged&& converged, bool& done) {
    constexpr int kMostReplicas = 12, kLargestBlockBits = 14;
    static_assert(uint64_t(8) << kLargestBlockBits == kSoftLightMaxRays);
    const double scale = measure == CapMeasure::Cosine
                             ? std::pow(std::sin(theta_max), 2)
                             : 2.0 * std::pow(std::sin(0.5 * theta_max), 2);
    Vec3 tx, ty;
    axis_frame(axis, tx, ty);
    const ScrambledSobol2D sequence(key);
    // Per thread, reused point after point (f traces shadow rays only, never a nested mean).
    thread_local std::vector<RoundPoint> points, ordered;
    thread_local std::vector<uint32_t> box_start;
    Value mean(0.0);
    done = true;
    Value sums[kMostReplicas];
    int traced = 0;  // blocks of the current size traced so far
    for (int bits = 1; bits <= kLargestBlockBits; ++bits) {
        const uint32_t block = 1u << bits;
        if (traced > 0) {  // the last size's blocks, paired: the first blocks of this size
            for (int r = 0; r < traced / 2; ++r) sums[r] = sums[2 * r] + sums[2 * r + 1];
            traced /= 2;
        }
        // 12 blocks of the largest size would pass the ray cap; 16 of the others are the next
        // size's 8.
        for (const int replicas : {8, 12}) {
            if (replicas == 12 && bits == kLargestBlockBits) break;
            // A round too small to stop is not traced (the first traced one starts the blocks).
            if (double(replicas) * block < min_samples && bits < kLargestBlockBits) continue;
            order_round(sequence, traced, replicas, block, points, ordered, box_start);
            for (int r = traced; r < replicas; ++r) sums[r] = Value(0.0);
            for (const RoundPoint& p : ordered) {
                double cos_t, sin_t, cos_phi, sin_phi;
                ring_angle(measure, scale, p.u, cos_t, sin_t);
                turn_cos_sin(p.v, cos_phi, sin_phi);
                sums[p.block] += f(cos_t * axis + sin_t * (cos_phi * tx + sin_phi * ty));
            }
            traced = replicas;
            Value sum(0.0), sum2(0.0);
            for (int r = 0; r < replicas; ++r) {
                const Value replica = sums[r] / double(block);
                sum += replica;
                sum2 += replica * replica;
            }
            mean = sum / double(replicas);
            const Value variance = glm::max(Value(0.0), (sum2 - sum * mean) / double(replicas - 1));
            const double t99 = replicas == 8 ? kStudent99 : kStudent99Of11;
            if (double(replicas) * block >= min_samples &&
                converged(variance / double(replicas), t99))
                return mean;
        }
    }
    done = false;
    return mean;
}

}  // namespace

double SoftLighting::sampled_share(const Vec3& p, const Vec3& p_error, const Vec3& ng,
                                   const Vec3& axis, double theta_max, CapMeasure measure,
                                   double reach, const Vec3& target, double target_radius,
                                   uint64_t key, double interval, double min_rays,
                                   SoftLightCounts& counts) const {
    ++counts.sampled_points;
    bool done = true;
    // Neighbouring directions are mostly blocked by the same primitive (a hint only).
    uint32_t blocker = UINT32_MAX;
    const double mean = stratified_mean<double>(
        axis, theta_max, measure, key, min_rays,
        [&](const Vec3& w) {
            return shadow_visibility(p, p_error, ng, w, reach, target, target_radius, counts,
                                     blocker);
        },
        [&](double v, double t99) { return t99 * std::sqrt(v) <= interval; }, done);
    if (!done) ++counts.unconverged;
    return mean;
}

Vec3 SoftLighting::sky_radiance(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& n,
                                SoftLightCounts& counts) const {
    // L = lowest + (L - lowest): the constant part by A(p) (a hard bound where the caps apply),
    // the rest, which is 0 on a constant map, by sampling it with the visibility.
    const SkyMap& map = *sky_map_;
    const Vec3 lowest = map.lowest(), range = map.highest() - lowest;
    Vec3 out(0.0);
    if (lowest.x > 0.0 || lowest.y > 0.0 || lowest.z > 0.0)
        out = lowest * sky_visibility(p, p_error, ng, n, counts);
    if (!(range.x > 0.0 || range.y > 0.0 || range.z > 0.0)) return out;
    ++counts.sampled_points;
    bool done = true;
    uint32_t blocker = UINT32_MAX;
    out += stratified_mean<Vec3>(
        n, 0.5 * kPi, CapMeasure::Cosine, point_key(seed_ ^ 0x5c1e5, p, n), min_rays_,
        [&](const Vec3& w) {
            const double v =
                shadow_visibility(p, p_error, ng, w, ao_distance_, Vec3(0.0), 0.0, counts, blocker);
            return v > 0.0 ? v * (map.radiance(w) - lowest) : Vec3(0.0);
        },
        [&](const Vec3& v, double t99) {
            const Vec3 half = t99 * glm::sqrt(v);
            return half.x <= point_interval_ * range.x && half.y <= point_interval_ * range.y &&
                   half.z <= point_interval_ * range.z;
        },
        done);
    if (!done) ++counts.unconverged;
    return out;
}

double SoftLighting::sky_visibility(const Vec3& p, const Vec3& p_error, const Vec3& ng,
                                    const Vec3& n, SoftLightCounts& counts) const {
    double share = 1.0;
    if (spheres_only_ &&
        exact_share(p, n, 0.5 * kPi, CapMeasure::Cosine, ao_distance_, -1.0, true, share, counts))
        return share;
    return sampled_share(p, p_error, ng, n, 0.5 * kPi, CapMeasure::Cosine, ao_distance_, Vec3(0.0),
                         0.0, point_key(seed_, p, n), point_interval_, min_rays_, counts);
}

double SoftLighting::shared_sky_visibility(const Vec3& p, const Vec3& p_error, const Vec3& ng,
                                           const Vec3& n, SoftLightCounts& counts) const {
    const double node = kSharedNodeShare * tolerance_;
    return sampled_share(p, p_error, ng, n, 0.5 * kPi, CapMeasure::Cosine, ao_distance_, Vec3(0.0),
                         0.0, point_key(seed_, p, n), node, min_samples_to_see(node), counts);
}

double SoftLighting::light_visibility(const Light& light, const Vec3& p, const Vec3& p_error,
                                      const Vec3& ng, SoftLightCounts& counts) const {
    Vec3 axis;
    double theta_max, reach = kInf, near = kInf, radius = 0.0;
    if (light.kind == LightKind::Directional) {
        axis = -light.direction;
        theta_max = light.angular_radius;
    } else {
        const Vec3 v = light.position - p;
        const double d = glm::length(v);
        radius = light.source_radius;
        if (!(d > radius)) return 1.0;  // inside the light: nothing lies between
        axis = v / d;
        theta_max = std::asin(radius / d);
        reach = d;
        near = d - radius;
    }
    double share = 1.0;
    if (spheres_only_ &&
        exact_share(p, axis, theta_max, CapMeasure::SolidAngle, reach, near, false, share, counts))
        return share;
    // A point in the gas has no surface: the whole light counts (every direction of its cone lies
    // within pi/2 of the axis).
    const Vec3 n = glm::dot(ng, ng) > 0.0 ? ng : axis;
    return sampled_share(p, p_error, n, axis, theta_max, CapMeasure::SolidAngle, reach,
                         light.position, radius, point_key(seed_ ^ 0x5eed, p, light.position),
                         point_interval_, min_rays_, counts);
}

}  // namespace vr
