#include "geometry/tri_mesh.h"

namespace vr {

double TriMesh::area() const {
    double sum = 0.0;
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const Vec3& a = positions[triangles[t]];
        sum += 0.5 * glm::length(glm::cross(positions[triangles[t + 1]] - a,
                                            positions[triangles[t + 2]] - a));
    }
    return sum;
}

}  // namespace vr
