// IndexedFaceSet semantics (VRML97 6.23, X3D 13.3.6) turned into triangles: polygons split by -1,
// convex or concave (ear clipping in each polygon's best-fit plane), ccw, per-vertex or per-face
// normals and colours with or without their own index, texture coordinates or the default mapping,
// creaseAngle smoothing.
//
// Interpretations:
// * A face with an out-of-range or non-finite coordinate, or with no area, is skipped (one warning
//   per cause).
// * An attribute (normal, colour, texture coordinate) whose indices are out of range or too few is
//   dropped for the whole mesh with one warning: the mesh renders with generated normals, the
//   material colour, or the default texture mapping.
// * creaseAngle: the normal at a corner is the mean of the unit normals of the faces around that
//   vertex (same coordinate index) whose normal makes an angle below creaseAngle with this face's;
//   creaseAngle 0 gives flat faces (TriMesh::normals left empty). `smooth_all` (X3D composed
//   geometry) averages every face around the vertex.
// * Default texture mapping: s along the bounding box's largest dimension, t along the second
//   largest (ties X, then Y, then Z), both divided by the largest size.
#pragma once
#include "geometry/tri_mesh.h"
#include "scene/report.h"
#include "scene/scene.h"

namespace vr {

// `want_uvs`: compute texture coordinates (only meshes under a texture need them).
TriMesh triangulate_face_set(const sg::IndexedFaceSet& faces, bool want_uvs, NodeReport& report);

// The default texture coordinates of a point inside the bounding box [lo, hi] (VRML97 6.23).
struct DefaultTexMapping {
    int s_axis = 0, t_axis = 1;
    Vec3 lo{0.0};
    double size = 0.0;  // the largest dimension
    static DefaultTexMapping from_bounds(const Vec3& lo, const Vec3& hi);
    Vec2 operator()(const Vec3& p) const;
};

}  // namespace vr
