#include "render/flat_scene.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

#include "core/parallel.h"

namespace vr {

namespace {
bool finite3(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
}  // namespace

// World bounds of everything the tracer can hit (gas spheres included). Non-finite data is left
// out, as the tracer leaves it out.
Bounds3 FlatScene::bounds(int threads) const {
    // Split over the threads: on a large molecule one core is slow enough to show in the scene
    // phase (bench/README.md, "Figures behind the comments"). min and max are exact, and c - r or c
    // + r is never -0 for r > 0, so the chunks do not change the bounds, not even a zero's sign.
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    const int chunks = chunks_for(spheres.size(), threads);
    std::vector<Bounds3> part(static_cast<size_t>(chunks));
    parallel_ranges(spheres.size(), chunks, [&](size_t begin, size_t end, int c) {
        Bounds3& p = part[size_t(c)];
        for (size_t i = begin; i < end; ++i) {
            const Sphere& s = spheres[i];
            if (!(s.radius > 0.0) || !std::isfinite(s.radius) || !finite3(s.center)) continue;
            p.extend(s.center - Vec3(s.radius));
            p.extend(s.center + Vec3(s.radius));
        }
    });
    Bounds3 b;
    for (const Bounds3& p : part) b.extend(p);
    for (const Quadric& q : quadrics) {
        Vec3 half = q.size * 0.5;
        if (!finite3(half)) continue;
        for (int c = 0; c < 8; ++c) {
            Vec3 corner((c & 1) ? half.x : -half.x, (c & 2) ? half.y : -half.y,
                        (c & 4) ? half.z : -half.z);
            Vec3 w = Vec3(q.world_from_object * Vec4(corner, 1.0));
            if (finite3(w)) b.extend(w);
        }
    }
    for (const LineSegment& s : segments)
        for (const Vec3& p : {s.a, s.b})
            if (finite3(p)) b.extend(p);
    for (const PointMark& p : points)
        if (finite3(p.position)) b.extend(p.position);
    for (const Mesh& m : meshes) {
        for (uint32_t index : m.triangles) {
            if (index < m.positions.size() && finite3(m.positions[index]))
                b.extend(m.positions[index]);
        }
    }
    for (const MeshInstance& in : instances) {
        if (in.prototype >= prototypes.size()) continue;
        const Mesh& m = prototypes[in.prototype];
        for (uint32_t index : m.triangles) {
            if (index >= m.positions.size()) continue;
            const Vec3 w = Vec3(in.world_from_object * Vec4(m.positions[index], 1.0));
            if (finite3(w)) b.extend(w);
        }
    }
    // X3D layers without a Viewpoint of their own are seen through this scene's camera (render/
    // layers.h), so they are framed with it.
    for (const FlatLayer& layer : layers)
        if (layer.scene && layer.scene->viewpoints.empty()) b.extend(layer.scene->bounds(threads));
    return b;
}

size_t FlatScene::triangle_count() const {
    size_t n = 0;
    for (const Mesh& m : meshes) n += m.triangle_count();
    return n;
}

size_t FlatScene::instanced_triangle_count() const {
    size_t n = 0;
    for (const MeshInstance& in : instances)
        if (in.prototype < prototypes.size()) n += prototypes[in.prototype].triangle_count();
    return n;
}

}  // namespace vr
