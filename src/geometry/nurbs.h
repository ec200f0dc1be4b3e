// NURBS curves and surfaces (X3D 19775-1 clause 27): checked, evaluated by de Boor's algorithm on
// homogeneous control points (rational, with weights), and tessellated.
//
// Tessellation: a curve or surface direction with `tessellation` T > 0 gets T uniform segments over
// its domain, T < 0 gets -T segments a control point (X3D 27.4.2 and 27.4.7). T = 0 (the default,
// "the browser's choice") gets enough segments, knot span by knot span, that the chordal error
// h^2 max|C''| / 8 of each segment of length h is at most kNurbsChordTolerance times the diagonal
// of the control points' bounding box (max|C''| estimated from second differences at 32 points a
// span), and never fewer than X3D's 2n segments for n control points. Surfaces take the finer of
// the needs of every iso-curve in each direction. Normals are exact: the cross product of the
// surface's partial derivatives, which de Boor's algorithm gives with the point.
#pragma once
#include <functional>
#include <vector>

#include "core/math.h"
#include "scene/report.h"
#include "scene/scene.h"

namespace vr {

inline constexpr double kNurbsChordTolerance = 5e-4;  // relative to the control net's size
inline constexpr int kNurbsMaxSegments = 1024;        // a direction's cap (hostile tessellation)
inline constexpr int kNurbsMaxOrder = 32;             // X3D sets no limit; real files use 2 to 6

// A curve ready to evaluate: control points as (w x, w y, w z, w), a valid knot vector (the
// file's, or uniform and clamped when the file's is missing or invalid), the degree.
struct RationalCurve {
    std::vector<Vec4> points;
    std::vector<double> knots;
    int degree = 0;
    double start() const { return knots[size_t(degree)]; }
    double end() const { return knots[points.size()]; }
};
// False (with a warning naming `what`) when the curve cannot be drawn: fewer control points than
// its order, an order below 2, non-finite points.
bool make_curve(const sg::NurbsCurve& curve, RationalCurve& out, NodeReport& report,
                const char* what);

struct CurveSample {
    Vec3 position;
    Vec3 derivative;  // dC/dt
};
// de Boor's algorithm at t (clamped to the domain).
CurveSample evaluate(const RationalCurve& curve, double t);

// The parameters one direction is sampled at, by the rule in this header's comment. `sample(t,
// out)` gives the points at parameter t whose chordal error is bounded (one point for a curve, a
// point on each of a surface's iso-curves across); `tolerance` is absolute.
using SampleAt = std::function<void(double, std::vector<Vec3>&)>;
std::vector<double> direction_parameters(const std::vector<double>& knots, int degree, int count,
                                         int tessellation, double tolerance,
                                         const SampleAt& sample);

// A NurbsCurve, NurbsCurve2D or ContourPolyline2D as a polyline (2D ones with z = 0).
std::vector<Vec3> curve_polyline(const sg::NurbsCurve& curve, NodeReport& report, const char* what);

// A tensor-product surface: control point (i, j) at points[i + j * u_count].
struct RationalSurface {
    std::vector<Vec4> points;
    std::vector<double> u_knots, v_knots;
    int u_degree = 0, v_degree = 0, u_count = 0, v_count = 0;
    double u_start() const { return u_knots[size_t(u_degree)]; }
    double u_end() const { return u_knots[size_t(u_count)]; }
    double v_start() const { return v_knots[size_t(v_degree)]; }
    double v_end() const { return v_knots[size_t(v_count)]; }
};
struct SurfaceSample {
    Vec3 position;
    Vec3 du, dv;  // partial derivatives
};
SurfaceSample evaluate(const RationalSurface& surface, double u, double v);

// The knot vector to use: `knots` when it has count + order non-decreasing finite values spanning
// a non-empty domain, else uniform and clamped on [0, 1] (warned about when `knots` was given).
std::vector<double> usable_knots(const std::vector<double>& knots, int count, int order,
                                 NodeReport& report, const char* what);

// Any NURBS surface node as faces with per-vertex normals (and texture coordinates when
// `want_uvs`); empty with a warning when it cannot be drawn.
sg::IndexedFaceSet nurbs_surface_faces(const sg::NurbsSurface& surface, bool want_uvs,
                                       NodeReport& report);

}  // namespace vr
