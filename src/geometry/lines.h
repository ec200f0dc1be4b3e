// IndexedLineSet, LineSet and PointSet as polylines and points with their colours, indices
// resolved and checked (VRML97 6.24 and 6.36, X3D 11.3.4 and 11.3.7).
//
// Interpretations:
// * IndexedLineSet: coordIndex polylines separated by -1. An out-of-range index breaks the polyline
//   there (one warning). Colours: colorPerVertex TRUE takes colorIndex per vertex (coordIndex when
//   colorIndex is empty), FALSE one colour a polyline (colorIndex per polyline, else in order).
// * LineSet: vertexCount consecutive coordinates a polyline; colours per vertex, in the same order.
//   A count below 2 is skipped; counts past the last coordinate stop the set (one warning each).
// * PointSet: every coordinate a point, coloured by the colour of the same index.
// * Colours whose indices are out of range or too few are dropped for the whole node (one
//   warning): the marks take the material's colour.
#pragma once
#include <cstdint>
#include <vector>

#include "core/math.h"
#include "scene/report.h"
#include "scene/scene.h"

namespace vr {

struct Polylines {
    std::vector<Vec3> positions;   // object space, finite
    std::vector<Vec3> colors;      // per position; empty: the material's colour
    std::vector<double> alphas;    // per position (ColorRGBA); empty: the material's opacity
    std::vector<uint32_t> starts;  // polyline i: positions [starts[i], starts[i + 1] or the end)
    bool points = false;           // PointSet: each position is a point, `starts` empty
};

Polylines line_geometry(const sg::LineSet& lines, NodeReport& report);

}  // namespace vr
