// Recognising a tessellated sphere: molecular exporters (Jmol) write every atom as a USE of one
// IndexedFaceSet approximating a sphere. When all its vertices lie on one sphere to the precision the file
// wrote them with, and they cover it all around, the exact sphere can stand in for the mesh.
#pragma once
#include <optional>
#include <vector>

#include "core/math.h"

namespace vr {

struct SphereFit {
    Vec3 center{0.0};
    double radius = 0.0;
};

// The sphere the points lie on, or nothing: fewer than 12 points, points off the least-squares sphere by
// more than the rounding of their written decimals (at most 1e-4 of the radius), or a part-sphere (the
// points must reach out to within 20% of the radius along every axis and all around the centre).
std::optional<SphereFit> fit_tessellated_sphere(const std::vector<Vec3>& points);

// The number of decimals the coordinates were written with (the smallest k <= 12 such that every value is
// a multiple of 10^-k to within double rounding), or 12.
int written_decimals(const std::vector<Vec3>& points);

}  // namespace vr
