// Triangulation of one planar-ish polygon, convex or concave, by ear clipping in its best-fit
// plane.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "core/math.h"

namespace vr {

// Newell's normal of a closed polygon: its direction is the best-fit plane's normal (right-hand
// rule over the vertex order) and its length twice the projected area. Exact for planar polygons.
Vec3 newell_normal(std::span<const Vec3> points);

// Appends triangles (triples of indices into `points`) covering the polygon, each counter-clockwise
// about the polygon's Newell normal. Handles concave polygons, collinear and repeated vertices.
// Returns false (appending nothing) when the polygon has no area: fewer than 3 distinct points, all
// collinear, or non-finite points. A self-intersecting polygon still gets triangles (their union
// then covers it only approximately).
bool triangulate_polygon(std::span<const Vec3> points, std::vector<uint32_t>& out);

}  // namespace vr
