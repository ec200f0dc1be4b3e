// X3D Geometry2D (ISO/IEC 19775-1 clause 14) as the geometry vrmlray already draws: the filled
// nodes (ArcClose2D, Disk2D, Rectangle2D, TriangleSet2D) as flat polygons in the z = 0 plane, front
// face +z, and the line and point nodes (Arc2D, Circle2D, Polyline2D, Polypoint2D) as the unlit
// marks of LineSet and PointSet.
//
// Arcs and circles are chords: a circle of radius r is cut into n equal steps with the sagitta
// r * (1 - cos(pi / n)) at most kArcSagitta * r (a relative error of 1e-4: 0.05 pixel on a disk a
// thousand pixels across). The polygon's area is then at most 4/3 * kArcSagitta short of the
// circle's (sin x / x >= 1 - x^2 / 6 with x^2 / 8 <= kArcSagitta).
#pragma once
#include <string_view>
#include <vector>

#include "scene/scene.h"

namespace vr::g2d {

inline constexpr double kArcSagitta = 1e-4;

// Chord steps for an arc sweeping `sweep` radians (0 < sweep <= 2 pi): at least 1, at most the
// steps of a full circle.
int arc_steps(double sweep);

// X3D 14.4.1: an arc runs counter-clockwise from startAngle to endAngle; equal angles (mod 2 pi)
// make a full circle. The sweep in (0, 2 pi].
double arc_sweep(double start_angle, double end_angle);

// Rectangle2D (14.4.6): corners at +-size/2, texture (0,0) at the lower left and (1,1) at the upper
// right corner.
sg::IndexedFaceSet rectangle_faces(Vec2 size, bool solid);

// TriangleSet2D (14.4.8): a triangle per three vertices (a remainder of one or two is ignored);
// texture coordinates map the vertices' bounding box onto [0,1]^2.
sg::IndexedFaceSet triangle_set_faces(const std::vector<Vec2>& vertices, bool solid);

// Disk2D (14.4.4): a disc (innerRadius 0) or a ring; texture coordinates map the outer circle's
// bounding square onto [0,1]^2. innerRadius == outerRadius is a circle (see disk_is_circle).
sg::IndexedFaceSet disk_faces(double inner_radius, double outer_radius, bool solid);
inline bool disk_is_circle(double inner, double outer) { return inner == outer; }

// ArcClose2D (14.4.2): the arc closed by two radii to the centre ("PIE") or by its chord ("CHORD");
// texture coordinates as Disk2D's.
sg::IndexedFaceSet arc_close_faces(double radius, double start_angle, double end_angle, bool pie,
                                   bool solid);

// Arc2D (14.4.1) and Circle2D (14.4.3): one polyline in z = 0 (a circle closes on its first point).
sg::LineSet arc_lines(double radius, double start_angle, double end_angle);
sg::LineSet circle_lines(double radius);
// Polyline2D (14.4.5): one polyline through the points; Polypoint2D (14.4.7): a point mark each.
sg::LineSet polyline_lines(const std::vector<Vec2>& points);
sg::LineSet point_marks(const std::vector<Vec2>& points);

// The area of a flat mesh's faces (for tests and checks): the sum of its polygons' shoelace areas.
double face_area(const sg::IndexedFaceSet& faces);

}  // namespace vr::g2d
