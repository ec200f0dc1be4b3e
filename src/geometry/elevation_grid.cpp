#include <cmath>
#include <string>

#include "geometry/mesh_nodes.h"

namespace vr {

sg::IndexedFaceSet elevation_grid_faces(const sg::ElevationGrid& grid, bool want_uvs,
                                        NodeReport& report) {
    sg::IndexedFaceSet faces;
    faces.ccw = grid.ccw;
    faces.solid = grid.solid;
    faces.convex = true;  // a grid cell is one quad, split along a diagonal like any convex face
    faces.color_per_vertex = grid.color_per_vertex;
    faces.normal_per_vertex = grid.normal_per_vertex;
    faces.crease_angle = grid.crease_angle;
    const int nx = grid.x_dimension, nz = grid.z_dimension;
    if (nx < 2 || nz < 2) {
        if (nx != 0 || nz != 0)
            report.warn("dimension", "xDimension and zDimension must both be at least 2 (got " +
                                         std::to_string(nx) + " x " + std::to_string(nz) +
                                         "); nothing to render");
        else
            report.warn("empty", "is empty; nothing to render");
        return faces;
    }
    const size_t vertices = size_t(nx) * size_t(nz);
    if (grid.height.size() < vertices) {
        report.warn("height-count", "has " + std::to_string(grid.height.size()) + " heights for " +
                                        std::to_string(nx) + " x " + std::to_string(nz) +
                                        " vertices; nothing to render");
        return faces;
    }
    if (!(grid.x_spacing > 0.0) || !(grid.z_spacing > 0.0) || !std::isfinite(grid.x_spacing) ||
        !std::isfinite(grid.z_spacing)) {
        report.warn("spacing",
                    "xSpacing and zSpacing must be positive and finite; nothing to render");
        return faces;
    }

    faces.data.coords.resize(vertices);
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i)
            faces.data.coords[size_t(i) + size_t(j) * nx] = Vec3(
                i * grid.x_spacing, grid.height[size_t(i) + size_t(j) * nx], j * grid.z_spacing);
    faces.coord_index.reserve(size_t(nx - 1) * (nz - 1) * 5);
    for (int j = 0; j + 1 < nz; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
            const int32_t v = i + j * nx;
            // Counter-clockwise seen from +Y: (i,j) -> (i,j+1) -> (i+1,j+1) -> (i+1,j).
            faces.coord_index.insert(faces.coord_index.end(), {v, v + nx, v + nx + 1, v + 1, -1});
        }
    faces.data.normals = grid.data.normals;
    faces.data.colors = grid.data.colors;
    faces.data.alphas = grid.data.alphas;
    faces.data.fog_depths = grid.data.fog_depths;
    faces.data.has_texcoord_node = grid.data.has_texcoord_node;
    if (!grid.data.texcoords.empty()) {
        faces.data.texcoords = grid.data.texcoords;
    } else if (want_uvs) {
        faces.data.texcoords.resize(vertices);
        for (int j = 0; j < nz; ++j)
            for (int i = 0; i < nx; ++i)
                faces.data.texcoords[size_t(i) + size_t(j) * nx] =
                    Vec2(double(i) / (nx - 1), double(j) / (nz - 1));
    }
    return faces;
}

}  // namespace vr
