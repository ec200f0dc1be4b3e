// Small builders for FlatScenes in the tracer's tests (no parser involved).
#pragma once
#include <cstdint>
#include <random>
#include <vector>

#include "render/flat_scene.h"

namespace vr::testing {

// A direction drawn uniformly on the unit sphere (a normal deviate per axis, normalised): the
// random rays of the BVH, culling and triangle-block tests.
inline Vec3 random_unit(std::mt19937_64& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    return glm::normalize(Vec3(n(rng), n(rng), n(rng)));
}

// Adds a material + shading (lit by light set `light_set`) and returns the shading index.
inline uint32_t add_shading(FlatScene& scene, const Material& m, uint32_t light_set = 0) {
    scene.materials.push_back(m);
    Shading s;
    s.material = uint32_t(scene.materials.size() - 1);
    s.light_set = light_set;
    scene.shadings.push_back(s);
    return uint32_t(scene.shadings.size() - 1);
}

// A scene with one (empty) light set and no headlight.
inline FlatScene empty_scene() {
    FlatScene scene;
    scene.headlight = false;
    scene.light_sets.emplace_back();
    return scene;
}

inline void add_light(FlatScene& scene, const Light& light, uint32_t light_set = 0) {
    scene.lights.push_back(light);
    scene.light_sets[light_set].push_back(uint32_t(scene.lights.size() - 1));
}

inline void add_sphere(FlatScene& scene, const Vec3& c, double r, uint32_t shading) {
    Sphere s;
    s.center = c;
    s.radius = r;
    s.shading = shading;
    scene.spheres.push_back(s);
}

// An axis-aligned rectangle as two triangles with the given per-corner colours (empty: none), front
// side facing +normal_axis... corners given counterclockwise as seen from the front.
inline void add_quad(FlatScene& scene, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                     uint32_t shading, const std::vector<Vec3>& corner_colors = {}) {
    Mesh m;
    m.positions = {a, b, c, d};
    m.triangles = {0, 1, 2, 0, 2, 3};
    if (corner_colors.size() == 4) {
        const auto& k = corner_colors;
        m.colors = {k[0], k[1], k[2], k[0], k[2], k[3]};
    }
    m.shading = shading;
    m.solid = false;
    scene.meshes.push_back(std::move(m));
}

inline Viewpoint look_from(const Vec3& position, double fov) {
    Viewpoint v;
    v.position = position;
    v.field_of_view = fov;
    return v;
}

}  // namespace vr::testing
