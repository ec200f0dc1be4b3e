#include "render/soft_lighting.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include "render/sampling.h"

namespace vr {
namespace {

constexpr uint32_t kLeafSize = 4;
constexpr size_t kMaxBounds = 64;
constexpr size_t kMaxMixedCaps = 256;

// Whether the cone about `axis` of half-angle (cos_a, sin_a) and the ball (c, r) seen from p can
// share a direction: the angle to the ball's centre is below the sum of the half-angles.
bool cone_meets_ball(const Vec3& p, const Vec3& axis, double cos_a, double sin_a, const Vec3& c,
                     double r) {
    const Vec3 v = c - p;
    const double d = glm::length(v);
    if (!(d > r)) return true;  // p inside the ball
    const double sin_b = r / d, cos_b = std::sqrt((d - r) * (d + r)) / d;
    const double sin_sum = sin_a * cos_b + cos_a * sin_b;
    if (!(sin_sum > 0.0)) return true;  // the half-angles sum to pi: every direction
    const double cos_sum = cos_a * cos_b - sin_a * sin_b;
    return glm::dot(v, axis) > cos_sum * d;
}

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

// The caps are sorted largest first; the number of them that containment is tested against.
constexpr size_t kLargest = 64;

// Whether cap c lies inside one of the first kLargest of `big`.
bool contained(const DirectionCap& c, const std::vector<DirectionCap>& big, size_t count) {
    for (size_t j = 0; j < std::min(count, kLargest); ++j) {
        const DirectionCap& b = big[j];
        // angle(c, b) + a_c <= a_b: cos(angle) >= cos(a_b - a_c), and a_b >= a_c.
        if (b.cos_half <= c.cos_half &&
            glm::dot(c.axis, b.axis) >= b.cos_half * c.cos_half + b.sin_half * c.sin_half)
            return true;
    }
    return false;
}

// Removes the caps that lie inside one of the largest caps (atoms behind a near neighbour): they
// close nothing more, and the cap integral's work grows with the number of caps.
void drop_contained(std::vector<DirectionCap>& caps) {
    if (caps.size() < 2) return;
    std::sort(caps.begin(), caps.end(),
              [](const DirectionCap& a, const DirectionCap& b) { return a.cos_half < b.cos_half; });
    size_t kept = 1;
    for (size_t i = 1; i < caps.size(); ++i)
        if (!contained(caps[i], caps, kept)) caps[kept++] = caps[i];
    caps.resize(kept);
}

// Balls that hold every non-sphere primitive: per triangle, and along each box, cylinder, cone
// or ellipsoid a row of balls whose caps hug it (a bond seen from its atom's surface stays out of
// most of the atom's sky).
std::vector<Sphere> bounding_balls(const FlatScene& scene) {
    std::vector<Sphere> balls;
    auto add = [&](const Vec3& c, double r) {
        Sphere s;
        s.center = c;
        s.radius = r;
        balls.push_back(s);
    };
    for (const Quadric& q : scene.quadrics) {
        // Object space: the box [-size/2, size/2], cut into slices along its longest axis.
        const Vec3 half = 0.5 * q.size;
        const Vec3 ex = Vec3(q.world_from_object * glm::dvec4(half.x, 0, 0, 0));
        const Vec3 ey = Vec3(q.world_from_object * glm::dvec4(0, half.y, 0, 0));
        const Vec3 ez = Vec3(q.world_from_object * glm::dvec4(0, 0, half.z, 0));
        const Vec3 centre = Vec3(q.world_from_object * glm::dvec4(0, 0, 0, 1));
        Vec3 e[3] = {ex, ey, ez};
        std::sort(e, e + 3,
                  [](const Vec3& a, const Vec3& b) { return glm::length(a) > glm::length(b); });
        const double across = std::max(glm::length(e[1] + e[2]), glm::length(e[1] - e[2]));
        const int slices =
            std::clamp(int(std::ceil(glm::length(e[0]) / std::max(across, 1e-300))), 1, 8);
        const Vec3 step = e[0] / double(slices);
        // A slice's farthest corner from its centre (the axes need not be orthogonal).
        double radius = 0.0;
        for (double a : {-1.0, 1.0})
            for (double b : {-1.0, 1.0})
                for (double c : {-1.0, 1.0})
                    radius = std::max(radius, glm::length(a * step + b * e[1] + c * e[2]));
        for (int k = 0; k < slices; ++k) {
            const double t = (2.0 * k + 1.0) / slices - 1.0;
            add(centre + t * e[0], radius * (1.0 + 1e-9));
        }
    }
    for (const Mesh& m : scene.meshes)
        for (size_t t = 0; t < m.triangle_count(); ++t) {
            const Vec3& a = m.positions[m.triangles[3 * t]];
            const Vec3& b = m.positions[m.triangles[3 * t + 1]];
            const Vec3& c = m.positions[m.triangles[3 * t + 2]];
            const Vec3 mid = (a + b + c) / 3.0;
            const double r =
                std::max({glm::length(a - mid), glm::length(b - mid), glm::length(c - mid)});
            add(mid, r * (1.0 + 1e-9) + 1e-12);
        }
    return balls;
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

void SphereOccluders::gather(const Vec3& p, const Vec3& axis, double cos_half, double sin_half,
                             double reach, std::vector<uint32_t>& out) const {
    if (nodes_.empty()) return;
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& n = nodes_[stack[--top]];
        if (glm::length(n.center - p) - n.radius >= reach) continue;
        if (!cone_meets_ball(p, axis, cos_half, sin_half, n.center, n.radius)) continue;
        if (n.count > 0) {
            for (uint32_t i = n.first; i < n.first + n.count; ++i) out.push_back(i);
            continue;
        }
        const uint32_t self = uint32_t(&n - nodes_.data());
        if (top + 2 > 64) {  // deeper than a median split of 2^32 spheres: never
            for (uint32_t i = n.first; i < uint32_t(centers_.size()); ++i) out.push_back(i);
            continue;
        }
        stack[top++] = n.right;
        stack[top++] = self + 1;
    }
}

SoftLighting::SoftLighting(const FlatScene& scene, const Accel& accel, const GasVolume* gas,
                           const RenderOptions& options)
    : accel_(accel),
      gas_(gas && !gas->empty() ? gas : nullptr),
      tolerance_(options.light_tolerance),
      ao_distance_(options.ao_distance),
      seed_(options.seed),
      sky_(options.sky.has_value()) {
    std::vector<Sphere> opaque;
    for (const Sphere& s : scene.spheres) {
        const uint32_t m =
            s.shading < scene.shadings.size() ? scene.shadings[s.shading].material : 0;
        if (!s.gas && !(m < scene.materials.size() && scene.materials[m].transparency > 0.0))
            opaque.push_back(s);
    }
    spheres_only_ = scene.quadrics.empty() && scene.meshes.empty() && scene.instances.empty() &&
                    gas_ == nullptr && opaque.size() == scene.spheres.size();
    mixed_ = !spheres_only_ && !opaque.empty();
    if (spheres_only_ || mixed_) occluders_.build(opaque);
    bounded_ = mixed_ && scene.instances.empty() && scene.segments.empty() &&
               scene.points.empty() && gas_ == nullptr && opaque.size() == scene.spheres.size();
    if (bounded_) others_.build(bounding_balls(scene));
}

bool SoftLighting::gather_bounds(const Vec3& p, const Vec3& axis, double theta_max, double reach,
                                 const std::vector<DirectionCap>& closed,
                                 std::vector<DirectionCap>& caps) const {
    thread_local std::vector<uint32_t> found;
    found.clear();
    caps.clear();
    others_.gather(p, axis, std::cos(theta_max), std::sin(theta_max), reach, found);
    for (uint32_t i : found) {
        DirectionCap cap;
        bool inside = false;
        if (!sphere_cap(p, others_.center(i), others_.radius(i), reach, cap, inside)) continue;
        if (inside) return false;
        // A bond behind an atom closes nothing the atom leaves open.
        if (!contained(cap, closed, closed.size())) caps.push_back(cap);
        // Past this many, testing a direction against them costs more than its ray.
        if (caps.size() > kMaxBounds) return false;
    }
    return true;
}

bool SoftLighting::gather_caps(const Vec3& p, const Vec3& axis, double theta_max, double reach,
                               double light_near, bool skip_own, std::vector<DirectionCap>& caps,
                               bool& inside) const {
    thread_local std::vector<uint32_t> found;
    found.clear();
    caps.clear();
    inside = false;
    const double cos_max = std::cos(theta_max), sin_max = std::sin(theta_max);
    occluders_.gather(p, axis, cos_max, sin_max, reach, found);
    // Dropping the contained caps of thousands costs more than the rays (see kMaxMixedCaps).
    if (mixed_ && found.size() > 8 * kMaxMixedCaps) return false;
    const bool to_light = light_near >= 0.0;
    for (uint32_t i : found) {
        const Vec3& c = occluders_.center(i);
        const double r = occluders_.radius(i);
        DirectionCap cap;
        if (!sphere_cap(p, c, r, to_light ? kInf : reach, cap, inside)) continue;
        if (inside) return true;
        if (to_light) {
            // Only what lies before the light counts; its hits lie between light_near and reach
            // (its centre's distance). An occluder that misses the light's cone is no matter (the
            // sphere under the point, say), one that straddles the light's depth is sampled.
            const double cos_sum = cos_max * cap.cos_half - sin_max * cap.sin_half;
            const double sin_sum = sin_max * cap.cos_half + cos_max * cap.sin_half;
            if (sin_sum > 0.0 && glm::dot(cap.axis, axis) <= cos_sum) continue;
            const double d = glm::length(c - p);
            if (d - r >= reach) continue;
            if (d + r > light_near) return false;
        }
        // The sphere the point lies on closes exactly the half space below its tangent plane.
        if (skip_own && cap.cos_half == 0.0 && glm::dot(cap.axis, axis) < -1.0 + 1e-9) continue;
        caps.push_back(cap);
    }
    drop_contained(caps);
    // Mixed scenes: past this many caps (a porous molecule seen whole, with no --ao-distance) the
    // cap integral costs more than the shadow rays it saves (S2: 2,600 caps a point, 8x slower).
    return !mixed_ || caps.size() <= kMaxMixedCaps;
}

double SoftLighting::share(const Vec3& p, const Vec3& p_error, const Vec3& ng, const Vec3& axis,
                           double theta_max, CapMeasure measure, double reach, double light_near,
                           const Vec3& target, double target_radius, uint64_t key,
                           SoftLightCounts& counts) const {
    thread_local std::vector<DirectionCap> caps;
    thread_local CapScratch scratch;
    bool inside = false;
    const bool skip_own = light_near < 0.0;
    if ((spheres_only_ || mixed_) &&
        gather_caps(p, axis, theta_max, reach, light_near, skip_own, caps, inside)) {
        ++counts.exact_points;
        if (inside) return 0.0;
        counts.caps += caps.size();
        // The two parts' bounds add up to the tolerance; spheres only: all of it for the caps.
        const double cap_tolerance = mixed_ ? 0.5 * tolerance_ : tolerance_;
        const double open =
            open_share(axis, theta_max, measure, caps, cap_tolerance, scratch).value;
        if (!mixed_ || !(open > 0.0)) return open;
        thread_local std::vector<DirectionCap> bounds;
        const bool culled = bounded_ && gather_bounds(p, axis, theta_max, reach, caps, bounds);
        if (culled && bounds.empty()) return open;  // nothing else lies in the cone
        const double closed_more = sampled_share(
            p, p_error, ng, axis, theta_max, measure, reach, target, target_radius, key,
            tolerance_ - cap_tolerance, &caps, culled ? &bounds : nullptr, counts);
        return std::clamp(open - closed_more, 0.0, 1.0);
    }
    return sampled_share(p, p_error, ng, axis, theta_max, measure, reach, target, target_radius,
                         key, tolerance_, nullptr, nullptr, counts);
}

double SoftLighting::sampled_share(const Vec3& p, const Vec3& p_error, const Vec3& ng,
                                   const Vec3& axis, double theta_max, CapMeasure measure,
                                   double reach, const Vec3& target, double target_radius,
                                   uint64_t key, double tolerance,
                                   const std::vector<DirectionCap>* closed,
                                   const std::vector<DirectionCap>* maybe,
                                   SoftLightCounts& counts) const {
    constexpr int kReplicas = 8;
    constexpr double kStudent99 = 3.4995;  // two-sided 99% quantile of Student's t, 7 dof
    constexpr double kLn100 = 4.6052;
    const double scale = measure == CapMeasure::Cosine
                             ? std::pow(std::sin(theta_max), 2)
                             : 2.0 * std::pow(std::sin(0.5 * theta_max), 2);
    const Vec3 helper = std::abs(axis.x) < 0.6 ? Vec3(1.0, 0.0, 0.0) : Vec3(0.0, 1.0, 0.0);
    const Vec3 tx = glm::normalize(glm::cross(helper, axis));
    const Vec3 ty = glm::cross(axis, tx);
    auto visible = [&](const Vec3& w) {
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
        double v = accel_.transmittance(ray);
        if (gas_ && v > 0.0) v *= std::exp(-gas_->optical_depth(ray));
        return std::isfinite(v) ? v : 0.0;
    };
    // The caps come largest first (drop_contained), so a closed direction is found early.
    auto in_caps = [](const std::vector<DirectionCap>& caps, const Vec3& w) {
        for (const DirectionCap& c : caps)
            if (glm::dot(w, c.axis) >= c.cos_half) return true;
        return false;
    };
    // Mixed scenes: what the rays close beyond the caps, where a bounding cap allows it.
    auto sample = [&](const Vec3& w) {
        if (!closed) return visible(w);
        if ((maybe && !in_caps(*maybe, w)) || in_caps(*closed, w)) return 0.0;
        return 1.0 - visible(w);
    };
    ++counts.sampled_points;
    double mean = 0.0;
    for (int m = 4, round = 0; m <= 128; m *= 2, ++round) {
        double sum = 0.0, sum2 = 0.0;
        for (int r = 0; r < kReplicas; ++r) {
            double replica = 0.0;
            for (int cell = 0; cell < m * m; ++cell) {
                const uint64_t index = 2 * uint64_t(cell);
                const double u = ((cell % m) + sample_uniform(key, r, round, index)) / m;
                const double phi =
                    2.0 * kPi * ((cell / m) + sample_uniform(key, r, round, index + 1)) / m;
                double cos_t, sin_t;
                ring_angle(measure, scale, u, cos_t, sin_t);
                const Vec3 w = cos_t * axis + sin_t * (std::cos(phi) * tx + std::sin(phi) * ty);
                replica += sample(w);
            }
            replica /= double(m * m);
            sum += replica;
            sum2 += replica * replica;
        }
        mean = sum / kReplicas;
        const double variance = std::max(0.0, (sum2 - sum * mean) / (kReplicas - 1));
        // A correction whose patterns all agree (nothing but the caps closes anything, say)
        // has no spread to judge by: it stops only once an occluder closing a share `tolerance`
        // would have been met with 99% probability, (1 - E)^n <= 0.01.
        const bool dense =
            !closed || variance > 0.0 || double(kReplicas) * m * m * tolerance >= kLn100;
        if (dense && kStudent99 * std::sqrt(variance / kReplicas) <= tolerance) return mean;
    }
    ++counts.unconverged;
    return mean;
}

double SoftLighting::sky_visibility(const Vec3& p, const Vec3& p_error, const Vec3& ng,
                                    const Vec3& n, SoftLightCounts& counts) const {
    return share(p, p_error, ng, n, 0.5 * kPi, CapMeasure::Cosine, ao_distance_, -1.0, Vec3(0.0),
                 0.0, point_key(seed_, p, n), counts);
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
    return share(p, p_error, ng, axis, theta_max, CapMeasure::SolidAngle, reach, near,
                 light.position, radius, point_key(seed_ ^ 0x5eed, p, light.position), counts);
}

}  // namespace vr
