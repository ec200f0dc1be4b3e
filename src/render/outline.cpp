#include "render/outline.h"

#include <algorithm>
#include <cmath>

namespace vr {

namespace {

// The distance from point q to the line through o along unit d.
double distance_to_line(const Vec3& q, const Vec3& o, const Vec3& d) {
    const Vec3 v = q - o;
    return glm::length(v - glm::dot(v, d) * d);
}

}  // namespace

bool outline_differ(const OutlineSample& a, const OutlineSample& b) {
    if (a.hit != b.hit) return true;
    if (!a.hit) return false;
    // How far apart the two rays pass at the surfaces: the scale a step in depth is measured
    // against, the same in scene units for a 1080p and a 4K image of the same view (the probe
    // ring is the same fraction of the view). Taken both ways so that the test is symmetric.
    const double spacing =
        std::max(distance_to_line(a.p, b.o, b.d), distance_to_line(b.p, a.o, a.d));
    const Vec3 between = b.p - a.p;
    const double step =
        std::max(std::fabs(glm::dot(between, a.n)), std::fabs(glm::dot(between, b.n)));
    if (step > kDepthStep * spacing) return true;
    const double turn = glm::dot(a.n, b.n);
    const double limit = a.shape == b.shape ? std::cos(kCreaseDegrees * kPi / 180.0)
                                            : std::cos(kSmoothJoinDegrees * kPi / 180.0);
    return turn < limit;
}

Outline::Outline(const Accel& accel, const CameraRays& rays, const RenderOptions& options)
    : accel_(accel), rays_(rays), color_(options.outline_color) {
    const double width = options.outline_width;
    if (!(width > 0.0) || !std::isfinite(width) || options.height <= 0) return;
    radius_ = 0.5 * width * double(options.height);
    for (int k = 0; k < kOutlineProbes; ++k) {
        const double angle = 2.0 * kPi * double(k) / double(kOutlineProbes);
        ring_[k] = radius_ * Vec2(std::cos(angle), std::sin(angle));
    }
}

OutlineSample Outline::sample(double x, double y, RayCounters& counters) const {
    const Ray ray = rays_(x, y);
    ++counters.primary;
    OutlineSample out;
    out.o = ray.o;
    out.d = ray.d;
    Hit hit;
    if (!accel_.intersect(ray, hit)) return out;
    const SurfaceHit s = accel_.surface(ray, hit, /*want_uv=*/false);
    out.hit = true;
    out.shape = accel_.shape_of(hit);
    out.p = s.p;
    // A two-sided mesh may face either way; seen from the camera its side does not matter.
    out.n = glm::dot(s.ng, ray.d) > 0.0 ? -s.ns : s.ns;
    return out;
}

bool Outline::on_edge(double x, double y, RayCounters& counters) const {
    const OutlineSample centre = sample(x, y, counters);
    for (const Vec2& offset : ring_)
        if (outline_differ(centre, sample(x + offset.x, y + offset.y, counters))) return true;
    return false;
}

SampleValue Outline::edge_value() const {
    SampleValue v;
    v.color = color_;
    v.alpha = 1.0;
    return v;
}

}  // namespace vr
