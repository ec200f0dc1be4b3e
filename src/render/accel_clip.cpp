// ClipPlane in the tracer (docs/rendering.md "ClipPlane"): a primitive under clip planes keeps
// only the roots of its ray whose points the planes keep, so a cut sphere shows the inside of its
// far half and a shadow ray passes through the part cut away. Scenes without planes never come
// here (Accel::intersect and transmittance test any_clip_ first).
#include <algorithm>

#include "render/accel.h"

namespace vr {

namespace {

bool kept(const std::vector<Vec4>& planes, const Ray& ray, double t) {
    const Vec3 p = ray.o + t * ray.d;
    for (const Vec4& plane : planes)
        if (glm::dot(Vec3(plane), p) + plane.w < 0.0) return false;
    return true;
}

}  // namespace

void Accel::build_clip_scopes() {
    prim_scope_.clear();
    any_clip_ = scene_ != nullptr && scene_->any_clip_planes();
    if (!any_clip_) return;
    prim_scope_.resize(prims_.size());
    for (size_t i = 0; i < prims_.size(); ++i) {
        Hit h;
        h.prim = prims_[i];
        const uint32_t scope = scene_->shadings[shading_of(h)].scope;
        prim_scope_[i] = scene_->scopes[scope].clip_planes.empty() ? 0 : scope;
    }
}

bool Accel::test_clipped(uint32_t entry, const Ray& ray, double inv_a, const TriangleRay& tri_ray,
                         double& t_max, Hit& hit) const {
    const uint32_t ref = prims_[entry];
    const uint32_t index = prim_index(ref);
    const uint32_t scope = prim_scope_[entry];
    static const std::vector<Vec4> none;
    const std::vector<Vec4>& planes = scope == 0 ? none : scene_->scopes[scope].clip_planes;
    switch (prim_kind(ref)) {
        case PrimKind::Sphere: {
            const SphereGeom& s = spheres_[index];
            double t[2];
            const int n = sphere_roots(ray.o, ray.d, inv_a, s.center, s.radius, t_max, t);
            for (int k = 0; k < n; ++k)  // ascending: the first kept root is the hit
                if (kept(planes, ray, t[k])) {
                    t_max = hit.t = t[k];
                    hit.prim = ref;
                    return true;
                }
            return false;
        }
        case PrimKind::Quadric: {
            double t[4];
            uint8_t part[4];
            const int n = quadric_roots(quadrics_[index], ray, t_max, t, part);
            int best = -1;
            for (int k = 0; k < n; ++k)
                if ((best < 0 || t[k] < t[best]) && kept(planes, ray, t[k])) best = k;
            if (best < 0) return false;
            t_max = hit.t = t[best];
            hit.prim = ref;
            hit.part = part[best];
            return true;
        }
        case PrimKind::Triangle: {
            double t, b1, b2;
            if (!triangle_hit(tri_ray, triangles_[index], t_max, t, b1, b2)) return false;
            if (!kept(planes, ray, t)) return false;
            t_max = hit.t = t;
            hit.prim = ref;
            hit.b1 = b1;
            hit.b2 = b2;
            return true;
        }
        case PrimKind::Instance: {
            // Never clipped: flattening keeps a mesh under clip planes in world space.
            double limit = t_max;
            Hit h;
            if (!test_instance(index, ray, limit, h)) return false;
            t_max = limit;
            hit = h;
            return true;
        }
    }
    return false;
}

int Accel::crossings_clipped(uint32_t entry, const Ray& ray, double inv_a,
                             const TriangleRay& tri_ray) const {
    const uint32_t ref = prims_[entry];
    const uint32_t index = prim_index(ref);
    const uint32_t scope = prim_scope_[entry];
    if (prim_kind(ref) == PrimKind::Instance) return instance_crossings(index, ray);
    static const std::vector<Vec4> none;
    const std::vector<Vec4>& planes = scope == 0 ? none : scene_->scopes[scope].clip_planes;
    double t[4];
    uint8_t part[4];
    int n = 0;
    switch (prim_kind(ref)) {
        case PrimKind::Sphere: {
            const SphereGeom& s = spheres_[index];
            n = sphere_roots(ray.o, ray.d, inv_a, s.center, s.radius, ray.t_max, t);
            break;
        }
        case PrimKind::Quadric:
            n = quadric_roots(quadrics_[index], ray, ray.t_max, t, part);
            break;
        case PrimKind::Triangle: {
            double b1, b2;
            n = triangle_hit(tri_ray, triangles_[index], ray.t_max, t[0], b1, b2) ? 1 : 0;
            break;
        }
        case PrimKind::Instance:
            break;
    }
    int count = 0;
    for (int k = 0; k < n; ++k) count += kept(planes, ray, t[k]) ? 1 : 0;
    return count;
}

bool Accel::intersect_clipped(const Ray& ray, Hit& hit) const {
    double t_max = ray.t_max;
    bool found = false;
    const double inv_a = 1.0 / glm::dot(ray.d, ray.d);
    const TriangleRay tri_ray = triangles_.empty() ? TriangleRay() : TriangleRay(ray);
    traverse_wide_bvh(bvh_, ray, t_max, [&](uint32_t first, uint32_t count, double& tm) {
        for (uint32_t i = first; i < first + count; ++i)
            if (test_clipped(i, ray, inv_a, tri_ray, tm, hit)) found = true;
        return false;
    });
    return found;
}

double Accel::transmittance_clipped(const Ray& ray, uint32_t* blocker) const {
    const double inv_a = 1.0 / glm::dot(ray.d, ray.d);
    const TriangleRay tri_ray = triangles_.empty() ? TriangleRay() : TriangleRay(ray);
    double t_max = ray.t_max;
    double result = 1.0;
    traverse_wide_bvh(bvh_, ray, t_max, [&](uint32_t first, uint32_t count, double&) {
        for (uint32_t i = first; i < first + count; ++i) {
            const int n = crossings_clipped(i, ray, inv_a, tri_ray);
            if (n == 0) continue;
            const double tr = any_transparent_ ? prim_transparency_[i] : 0.0;
            if (tr <= 0.0) {
                result = 0.0;
                if (blocker != nullptr) *blocker = i;
                return true;
            }
            for (int k = 0; k < n; ++k) result *= tr;
        }
        return false;
    });
    return result;
}

}  // namespace vr
