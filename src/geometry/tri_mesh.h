// Triangles in object space with per-corner attributes: what the polygon geometry nodes become. The
// flattening step transforms a TriMesh into world space once per use of its geometry node.
#pragma once
#include <cstdint>
#include <vector>

#include "core/math.h"

namespace vr {

struct TriMesh {
    std::vector<Vec3> positions;  // object space, all finite
    std::vector<uint32_t>
        triangles;  // 3 position indices a triangle, counter-clockwise seen from the front
    std::vector<Vec3>
        normals;               // per corner (3 a triangle), unit, object space; empty: flat shading
    std::vector<Vec2> uvs;     // per corner; empty: none
    std::vector<Vec3> colors;  // per corner; empty: the material's colour
    std::vector<double> alphas;      // per corner with `colors` (ColorRGBA); empty: RGB colours
    std::vector<double> fog_depths;  // per corner (FogCoordinate); empty: none
    bool solid = true;               // false: two-sided
    size_t triangle_count() const { return triangles.size() / 3; }
    double area() const;  // sum of triangle areas (tests, info)
};

}  // namespace vr
