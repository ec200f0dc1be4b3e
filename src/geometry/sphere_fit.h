// Recognising a tessellated sphere: molecular exporters (Jmol) write every atom as a USE of one
// IndexedFaceSet approximating a sphere. When all its vertices lie on one sphere to the precision
// the file wrote them with, and the mesh covers it all around, the exact sphere can stand in for
// the mesh.
//
// "To the precision written": a coordinate written with k decimals stands for any value within half
// a unit of the k-th decimal, so a vertex agrees with a surface when the box of those values around
// it meets the surface. Of the spheres every vertex agrees with, the one reported is the writer's:
// the centre with the fewest decimals (0 0 0 for Jmol's unit sphere), then the radius with the
// fewest (exactly 1), falling back to the least-squares fit.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "core/math.h"

namespace vr {

struct SphereFit {
    Vec3 center{0.0};
    double radius = 0.0;
};

// Why a mesh is not taken for an exact shape. Ordered from the least to the most specific: of two
// attempted shapes (sphere, cylinder), the later reason says more about the mesh.
enum class FitFailure : uint8_t {
    OffSurface,       // a vertex is off the shape by more than its written decimals explain
    TooFewPoints,     // fewer than 12 vertices: too coarse to say
    CoarselyWritten,  // half a unit of the last written decimal exceeds 1e-3 of the radius
    NotAllAround,     // a part of the shape (a cap, a half, a hole of more than 10% of the area)
    PartialCap,       // a cylinder end covered by triangles, but not the whole disc
};
const char* fit_failure_label(FitFailure f);

// The number of decimals the coordinates were written with (the smallest k <= 12 such that every
// value is a multiple of 10^-k to within double rounding), or 12.
int written_decimals(const std::vector<Vec3>& points);

// Half a unit in the last written decimal of the points (plus double rounding): the half-width of
// the box each written coordinate stands for.
double written_half_unit(const std::vector<Vec3>& points);

// The value with the fewest decimals (at most `max_decimals`) in [lo, hi], the one nearest the
// middle among those; the middle when none has so few. Requires lo <= hi.
double roundest_in(double lo, double hi, int max_decimals);

// The sphere the points lie on (see above), or nothing with the reason in `why` (when not null):
// fewer than 12 points, a point that does not agree with any sphere near the least-squares one, a
// precision coarser than 1e-3 of the radius, or a part-sphere (the points must reach out to within
// 20% of the radius along every axis). `triangles` (3 indices a triangle, optional): the mesh must
// also cover at least 90% of the sphere's area, which a large hole or a tessellation as coarse as
// an icosahedron (76%) does not; Jmol's 162-vertex sphere covers 98.1%.
std::optional<SphereFit> fit_tessellated_sphere(const std::vector<Vec3>& points,
                                                const std::vector<uint32_t>* triangles = nullptr,
                                                FitFailure* why = nullptr);

// Summed area of the triangles (3 indices into `points` a triangle).
double triangles_area(const std::vector<Vec3>& points, const std::vector<uint32_t>& triangles);

}  // namespace vr
