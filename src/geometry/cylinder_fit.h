// Recognising a tessellated cylinder: Jmol writes every bond (half) as a USE of one IndexedFaceSet
// approximating a unit cylinder along y, placed by a rotated, non-uniformly scaled Transform. When
// every vertex lies on one axis-aligned cylinder to the precision the file wrote it with
// (sphere_fit.h says what agreeing means), the exact cylinder can stand in for the mesh, with the
// roundest values the vertices agree with (Jmol's radius 1, height 1).
//
// Other exporters write cylinders along any direction, rotated or baked into world coordinates.
// Failing the three axes, the axis is found (candidates from the triangles' normals and the
// vertices' spread, refined through the centres of the two end rings) and every vertex must lie
// within twice its own possible error of the side or an end disc: the error being half a unit of
// the last written decimal plus four single-precision roundings (a float32 exporter's 4x4
// transform of the vertex) on each coordinate, which moves a vertex by up to that times |n|_1
// along the surface normal n. Once for the vertex, once for the fitted cylinder, which is fitted
// from such vertices.
//
// Open and closed ends follow the mesh: an end whose plane holds triangles covering the disc is a
// cap, an end with no triangles in its plane is open (a tube), anything between is refused. An open
// end looks the same either way in this tracer (both sides of a surface are shaded, the inside of a
// tube included), so the only thing recovery changes is the faceting.
#pragma once
#include <optional>
#include <vector>

#include "geometry/sphere_fit.h"

namespace vr {

struct CylinderFit {
    int axis = 1;             // the object axis it runs along: 0 x, 1 y, 2 z; -1 another one
    Vec3 direction{0, 1, 0};  // the unit direction it runs along, from bottom to top
    Vec3 center{0.0};         // the middle of its axis, object space
    double radius = 0.0;      //
    double height = 0.0;      // along `direction`
    bool top = true;          // a disc closes the +direction end
    bool bottom = true;       // a disc closes the -direction end
};

// The cylinder the mesh lies on, or nothing with the reason in `why` (when not null). Needs at
// least 12 vertices, every vertex on the side or on an end disc, the side covered all around (rims
// at both ends reaching within 20% of the radius along both cross axes; side triangles covering 90%
// of the side's area), each end's triangles covering none or 90% of its disc, and a precision finer
// than 1e-3 of the radius.
std::optional<CylinderFit> fit_tessellated_cylinder(const std::vector<Vec3>& points,
                                                    const std::vector<uint32_t>& triangles,
                                                    FitFailure* why = nullptr);

// The rotation (unit axis, angle in radians) that turns +y, where a Cylinder node runs, onto the
// fit's direction: the one value both the renderer's recovery and `convert` place it with, so
// that the two compose the same matrix (scene/transform.h, transform_matrix).
Vec4 rotation_onto_direction(const CylinderFit& fit);

}  // namespace vr
