// The other polygon geometry nodes rewritten as IndexedFaceSets, so that one triangulator
// (polygon_mesh.h) handles indices, attributes, ccw and creaseAngle for all of them.
#pragma once
#include "geometry/tri_mesh.h"
#include "scene/report.h"
#include "scene/scene.h"

namespace vr {

// ElevationGrid (VRML97 6.17): vertex (i, j) at (i*xSpacing, height[i + j*xDimension], j*zSpacing);
// one quad per grid cell, front face up (+Y) for ccw TRUE. Per-face colours/normals go one a cell,
// row by row. Default texture coordinates: s = i/(xDimension-1), t = j/(zDimension-1) (computed
// when `want_uvs`).
sg::IndexedFaceSet elevation_grid_faces(const sg::ElevationGrid& grid, bool want_uvs,
                                        NodeReport& report);

// Extrusion (VRML97 6.18), see extrusion.cpp for the spine-aligned cross-section plane rules.
sg::IndexedFaceSet extrusion_faces(const sg::Extrusion& extrusion, bool want_uvs,
                                   NodeReport& report);

// X3D triangle/quad set family (X3D 11.4). Each triangle (quad for the quad sets) is one face for
// per-face colours and normals, including the triangles of fans and strips. Without a Normal node
// and with normalPerVertex TRUE, normals are averaged over the faces sharing a vertex (X3D 11.4.x:
// "the average of the normals of all triangles that share that vertex"); otherwise faces are flat.
sg::IndexedFaceSet composed_faces(const sg::ComposedSet& set, NodeReport& report);

// Any polygon geometry node -> object-space triangles (dispatch for the flattening step). Spheres,
// boxes, cylinders and cones are not meshes and give an empty result.
TriMesh triangulate_geometry(const sg::Geometry& geometry, bool want_uvs, Diagnostics& diagnostics);

}  // namespace vr
