// Accel::test_primitive, for the files of the Accel (accel.cpp, accel_blocks.cpp): the closest-hit
// test of one entry, inlined into their traversal loops.
#pragma once
#include "render/accel.h"

namespace vr {

inline bool Accel::test_primitive(uint32_t ref, const Ray& ray, double inv_a,
                                  const TriangleRay& tri_ray, double& t_max, Hit& hit) const {
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
        case PrimKind::Instance:
            return test_instance(index, ray, t_max, hit);
    }
    return false;
}

}  // namespace vr
