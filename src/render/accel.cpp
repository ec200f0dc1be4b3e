#include "render/accel.h"

#include <algorithm>
#include <cmath>

namespace vr {
namespace {

struct Source {
    PrimKind kind;
    uint32_t index;     // sphere, quadric or mesh
    uint32_t triangle;  // triangles only
};

bool finite3(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// One more float ulp outwards than make_build_box: covers the rounding of the double bounds.
BuildBox padded_box(const Vec3& lo, const Vec3& hi, uint32_t id) {
    BuildBox b = make_build_box(lo, hi, id);
    for (int k = 0; k < 3; ++k) {
        b.lo[k] = std::nextafter(b.lo[k], -INFINITY);
        b.hi[k] = std::nextafter(b.hi[k], INFINITY);
    }
    return b;
}

double material_transparency(const FlatScene& scene, uint32_t shading) {
    if (shading >= scene.shadings.size()) return 0.0;
    uint32_t m = scene.shadings[shading].material;
    if (m >= scene.materials.size()) return 0.0;
    double t = scene.materials[m].transparency;
    return std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
}

}  // namespace

void Accel::build(const FlatScene& scene, int threads) {
    scene_ = &scene;
    std::vector<Source> sources;
    std::vector<BuildBox> boxes;
    size_t triangle_total = scene.triangle_count();
    sources.reserve(scene.spheres.size() + scene.quadrics.size() + triangle_total);
    boxes.reserve(sources.capacity());

    for (uint32_t i = 0; i < scene.spheres.size(); ++i) {
        const Sphere& s = scene.spheres[i];
        if (!(s.radius > 0.0) || !std::isfinite(s.radius) || !finite3(s.center)) continue;
        boxes.push_back(padded_box(s.center - Vec3(s.radius), s.center + Vec3(s.radius), uint32_t(sources.size())));
        sources.push_back({PrimKind::Sphere, i, 0});
    }
    for (uint32_t i = 0; i < scene.quadrics.size(); ++i) {
        const Quadric& q = scene.quadrics[i];
        Vec3 half = q.size * 0.5;
        if (!finite3(half) || half.x < 0.0 || half.y < 0.0 || half.z < 0.0) continue;
        Vec3 lo(kInf), hi(-kInf);
        for (int c = 0; c < 8; ++c) {
            Vec3 corner((c & 1) ? half.x : -half.x, (c & 2) ? half.y : -half.y, (c & 4) ? half.z : -half.z);
            Vec3 w = Vec3(q.world_from_object * Vec4(corner, 1.0));
            lo = glm::min(lo, w);
            hi = glm::max(hi, w);
        }
        if (!finite3(lo) || !finite3(hi)) continue;
        boxes.push_back(padded_box(lo, hi, uint32_t(sources.size())));
        sources.push_back({PrimKind::Quadric, i, 0});
    }
    for (uint32_t mi = 0; mi < scene.meshes.size(); ++mi) {
        const Mesh& m = scene.meshes[mi];
        const size_t nt = m.triangle_count();
        for (uint32_t t = 0; t < nt; ++t) {
            uint32_t a = m.triangles[3 * t], b = m.triangles[3 * t + 1], c = m.triangles[3 * t + 2];
            if (a >= m.positions.size() || b >= m.positions.size() || c >= m.positions.size()) continue;
            const Vec3 &p0 = m.positions[a], &p1 = m.positions[b], &p2 = m.positions[c];
            if (!finite3(p0) || !finite3(p1) || !finite3(p2)) continue;
            boxes.push_back(padded_box(glm::min(p0, glm::min(p1, p2)), glm::max(p0, glm::max(p1, p2)),
                                       uint32_t(sources.size())));
            sources.push_back({PrimKind::Triangle, mi, t});
        }
    }

    BvhBuildOptions options;
    options.threads = std::max(threads, 1);
    bvh_ = build_bvh(std::move(boxes), options);

    prims_.clear();
    prim_transparency_.clear();
    spheres_.clear();
    sphere_source_.clear();
    quadrics_.clear();
    quadric_source_.clear();
    triangles_.clear();
    triangle_mesh_.clear();
    triangle_index_.clear();
    any_transparent_ = false;
    prims_.reserve(bvh_.order.size());
    prim_transparency_.reserve(bvh_.order.size());
    for (uint32_t id : bvh_.order) {
        const Source& s = sources[id];
        uint32_t shading = 0;
        switch (s.kind) {
            case PrimKind::Sphere: {
                const Sphere& sp = scene.spheres[s.index];
                prims_.push_back(pack_prim(PrimKind::Sphere, uint32_t(spheres_.size())));
                spheres_.push_back({sp.center, sp.radius});
                sphere_source_.push_back(s.index);
                shading = sp.shading;
                break;
            }
            case PrimKind::Quadric: {
                const Quadric& q = scene.quadrics[s.index];
                prims_.push_back(pack_prim(PrimKind::Quadric, uint32_t(quadrics_.size())));
                quadrics_.push_back(make_quadric_geom(q));
                quadric_source_.push_back(s.index);
                shading = q.shading;
                break;
            }
            case PrimKind::Triangle: {
                const Mesh& m = scene.meshes[s.index];
                const uint32_t* c = &m.triangles[3 * s.triangle];
                prims_.push_back(pack_prim(PrimKind::Triangle, uint32_t(triangles_.size())));
                triangles_.push_back({m.positions[c[0]], m.positions[c[1]], m.positions[c[2]]});
                triangle_mesh_.push_back(s.index);
                triangle_index_.push_back(s.triangle);
                shading = m.shading;
                break;
            }
        }
        // Gas spheres block shadow rays like opaque ones until the gas integrator handles them.
        float t = float(material_transparency(scene, shading));
        prim_transparency_.push_back(t);
        if (t > 0.0f) any_transparent_ = true;
    }
}

inline bool Accel::test_primitive(uint32_t ref, const Ray& ray, double inv_a, const TriangleRay& tri_ray,
                                  double& t_max, Hit& hit) const {
    const uint32_t index = prim_index(ref);
    switch (prim_kind(ref)) {
        case PrimKind::Sphere: {
            const SphereGeom& s = spheres_[index];
            double t[2];
            if (sphere_roots(ray.o, ray.d, inv_a, s.center, s.radius, t_max, t) == 0) return false;
            t_max = t[0];
            hit.t = t[0];
            hit.prim = ref;
            return true;
        }
        case PrimKind::Quadric: {
            double t[4];
            uint8_t part[4];
            int n = quadric_roots(quadrics_[index], ray, t_max, t, part);
            if (n == 0) return false;
            int best = 0;
            for (int i = 1; i < n; ++i)
                if (t[i] < t[best]) best = i;
            t_max = t[best];
            hit.t = t[best];
            hit.prim = ref;
            hit.part = part[best];
            return true;
        }
        case PrimKind::Triangle: {
            double t, b1, b2;
            if (!triangle_hit(tri_ray, triangles_[index], t_max, t, b1, b2)) return false;
            t_max = t;
            hit.t = t;
            hit.prim = ref;
            hit.b1 = b1;
            hit.b2 = b2;
            return true;
        }
    }
    return false;
}

int Accel::crossings(uint32_t ref, const Ray& ray, double inv_a, const TriangleRay& tri_ray) const {
    const uint32_t index = prim_index(ref);
    switch (prim_kind(ref)) {
        case PrimKind::Sphere: {
            const SphereGeom& s = spheres_[index];
            double t[2];
            return sphere_roots(ray.o, ray.d, inv_a, s.center, s.radius, ray.t_max, t);
        }
        case PrimKind::Quadric: {
            double t[4];
            uint8_t part[4];
            return quadric_roots(quadrics_[index], ray, ray.t_max, t, part);
        }
        case PrimKind::Triangle: {
            double t, b1, b2;
            return triangle_hit(tri_ray, triangles_[index], ray.t_max, t, b1, b2) ? 1 : 0;
        }
    }
    return 0;
}

bool Accel::intersect(const Ray& ray, Hit& hit) const {
    const double inv_a = 1.0 / glm::dot(ray.d, ray.d);
    const TriangleRay tri_ray(ray);
    double t_max = ray.t_max;
    bool found = false;
    traverse_bvh(bvh_, ray, t_max, [&](uint32_t first, uint32_t count, double& tm) {
        for (uint32_t i = first; i < first + count; ++i)
            if (test_primitive(prims_[i], ray, inv_a, tri_ray, tm, hit)) found = true;
        return false;
    });
    return found;
}

double Accel::transmittance(const Ray& ray) const {
    const double inv_a = 1.0 / glm::dot(ray.d, ray.d);
    const TriangleRay tri_ray(ray);
    double t_max = ray.t_max;
    double result = 1.0;
    if (!any_transparent_) {
        Hit hit;
        traverse_bvh(bvh_, ray, t_max, [&](uint32_t first, uint32_t count, double& tm) {
            for (uint32_t i = first; i < first + count; ++i) {
                double t_limit = ray.t_max;
                if (test_primitive(prims_[i], ray, inv_a, tri_ray, t_limit, hit)) {
                    result = 0.0;
                    return true;
                }
            }
            return false;
        });
        return result;
    }
    traverse_bvh(bvh_, ray, t_max, [&](uint32_t first, uint32_t count, double& tm) {
        for (uint32_t i = first; i < first + count; ++i) {
            int n = crossings(prims_[i], ray, inv_a, tri_ray);
            if (n == 0) continue;
            double tr = prim_transparency_[i];
            if (tr <= 0.0) {
                result = 0.0;
                return true;
            }
            for (int k = 0; k < n; ++k) result *= tr;
        }
        return false;
    });
    return result;
}

SurfaceHit Accel::surface(const Ray& ray, const Hit& hit) const {
    const uint32_t index = prim_index(hit.prim);
    switch (prim_kind(hit.prim)) {
        case PrimKind::Sphere:
            return sphere_surface(scene_->spheres[sphere_source_[index]], ray, hit.t);
        case PrimKind::Quadric:
            return quadric_surface(scene_->quadrics[quadric_source_[index]], quadrics_[index], ray, hit.t,
                                   hit.part);
        case PrimKind::Triangle:
            return triangle_surface(scene_->meshes[triangle_mesh_[index]], triangle_index_[index], ray,
                                    hit.t, hit.b1, hit.b2);
    }
    return SurfaceHit();
}

bool Accel::intersect_brute_force(const Ray& ray, Hit& hit) const {
    const double inv_a = 1.0 / glm::dot(ray.d, ray.d);
    const TriangleRay tri_ray(ray);
    double t_max = ray.t_max;
    bool found = false;
    for (uint32_t ref : prims_)
        if (test_primitive(ref, ray, inv_a, tri_ray, t_max, hit)) found = true;
    return found;
}

}  // namespace vr
