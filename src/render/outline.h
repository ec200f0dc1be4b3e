// Outlines (--outline; docs/rendering.md "Outlines"): black lines around each shape and where
// surfaces fold, as molecular viewers draw them (PyMOL's ray_trace_mode 1). Each camera sample
// decides on its own whether it lies on an edge, from the first hits of rays traced through it and
// through a ring of probe points around it on the image plane; an edge sample takes the outline
// colour instead of its shading, so the sampler that averages the samples antialiases the lines.
// Nothing here looks at an image: the decision comes from the traced shapes, depths and normals.
#pragma once
#include <cstdint>

#include "core/math.h"
#include "render/accel.h"
#include "render/camera.h"
#include "render/integrator.h"
#include "render/options.h"

namespace vr {

// Probe points around a sample: enough directions that a straight edge closer than
// cos(pi / kOutlineProbes) of the probe radius is always seen (92% for 8), so the line's width
// varies by at most that much with its direction.
inline constexpr int kOutlineProbes = 8;
// Two surfaces of one shape meet in a crease when their normals turn by more than this: a box's
// edges (90 degrees) and a ribbon's rims are creases, the facets of a coarse tessellation without
// normals (an icosphere's 42 degrees) are not.
inline constexpr double kCreaseDegrees = 60.0;
// Two different shapes that meet with their normals within this angle and without a step in depth
// continue one another (the two coloured halves of a stick, a cartoon cut into pieces): no line.
// Spheres meeting in a molecule turn by far more (two carbon atoms of a spacefill model: 54).
inline constexpr double kSmoothJoinDegrees = 20.0;
// A step in depth larger than this many times the distance between the sample's and the probe's
// rays, measured along either surface's normal, is a fold or an overlap: an edge. A plane at any
// slant steps by 0, a sphere seen from outside by less than that distance (1 - cos of the angle
// its normals turn is at most the probe's share of the radius), a ribbon in front of the same
// mesh's next turn by the gap between them.
inline constexpr double kDepthStep = 2.0;

// What the ray through one image point sees first.
struct OutlineSample {
    bool hit = false;
    uint32_t shape = 0;   // Accel::shape_of
    Vec3 p{0.0};          // world point
    Vec3 n{0.0};          // shading normal, unit, turned to face the ray's origin
    Vec3 o{0.0}, d{0.0};  // the ray (unit direction)
};

// Whether two samples of neighbouring image points lie on different sides of an edge: one sees a
// surface and the other none, or they see surfaces separated by a step in depth, a crease, or the
// boundary between two shapes that do not continue one another. Symmetric.
bool outline_differ(const OutlineSample& a, const OutlineSample& b);

class Outline {
  public:
    // Off (enabled() false) when options.outline_width is 0.
    Outline(const Accel& accel, const CameraRays& rays, const RenderOptions& options);
    bool enabled() const { return radius_ > 0.0; }
    // The probe ring's radius in pixels: half the line's width, which is options.outline_width of
    // the image height (so a 4K image shows the lines a 1080p one does, at twice the pixels).
    double radius_pixels() const { return radius_; }
    // The sample at image point (x, y) lies on an edge: some probe point within radius_pixels()
    // sees the other side of one. Counts its rays as primary rays.
    bool on_edge(double x, double y, RayCounters& counters) const;
    // The value of a sample on an edge: the outline colour, opaque.
    SampleValue edge_value() const;
    OutlineSample sample(double x, double y, RayCounters& counters) const;

  private:
    const Accel& accel_;
    const CameraRays& rays_;
    double radius_ = 0.0;
    Vec3 color_{0.0};
    Vec2 ring_[kOutlineProbes];  // probe offsets, pixels
};

}  // namespace vr
