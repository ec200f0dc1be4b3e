// Triangles covering a set of closed planar contours under the nonzero winding rule: outlines with
// holes and overlapping parts (font glyphs), which ear clipping of one polygon does not handle.
//
// The method is an exact trapezoidal decomposition: the plane is cut into horizontal slabs at
// every vertex height and every height where two edges cross, so that no edge crosses another
// inside a slab; in each slab the edges are ordered by x and the spans of nonzero winding become
// one trapezoid (two triangles) each. The union of the triangles is the filled region exactly (up
// to rounding of the crossing heights), with no triangle outside it.
#pragma once
#include <cstdint>
#include <vector>

#include "core/math.h"

namespace vr {

struct FlatTriangles {
    std::vector<Vec2> points;
    std::vector<uint32_t> triangles;  // 3 indices a triangle, counter-clockwise (x right, y up)
};

// `contours`: closed polylines (the last point joins the first); any orientation, the winding
// number of a point being the sum over contours. Non-finite points make the contour skipped.
FlatTriangles fill_nonzero(const std::vector<std::vector<Vec2>>& contours);

}  // namespace vr
