// Lines and points as the camera sees them: marks of a constant width on the screen, which have no
// area in the scene and so no place in the BVH. A camera ray meets a segment when its image-plane
// point lies within half the line width (in pixels) of the segment's projection, and a point when
// it lies within half the point size of its projection; the mark is then seen if it is no further
// along the ray than the first surface (plus one line width at that depth, so that lines drawn on a
// face stay visible, as a browser's polygon offset keeps them). Depth and colour along a segment
// are interpolated perspective-correctly. Every sample ray of every sampler is tested exactly, so
// the samplers anti-alias the marks like any edge. The marks are unlit (their colour is emissive)
// and are seen by camera rays only: they cast no shadow and appear in no reflection.
#pragma once
#include <cstdint>
#include <vector>

#include "core/ray.h"
#include "render/camera.h"
#include "render/flat_scene.h"

namespace vr {

class LineOverlay {
  public:
    LineOverlay() = default;
    LineOverlay(const FlatScene& scene, const Camera& camera, int width, int height,
                double line_width, double point_size);
    bool empty() const { return marks_.empty(); }
    // The nearest mark on camera ray `ray` (unit direction) no further than `t_surface` (+inf: no
    // surface), with its colour and opacity there; false if none.
    bool nearest(const Ray& ray, double t_surface, Vec3& color, double& alpha) const;

  private:
    // A segment or point projected to the image: pixel coordinates and camera depth of both ends.
    struct Mark {
        Vec2 a, b;              // pixels (x right, y down)
        double za = 0, zb = 0;  // depth along the view axis (perspective) or 1 (ortho)
        Vec3 pa, pb;            // world
        Vec3 ca, cb;            // colours
        double aa = 1, ab = 1;  // opacities
        double radius = 0;      // pixels
    };
    bool project(const Vec3& world, Vec2& pixel, double& depth) const;
    void add(const Mark& mark);
    Vec2 pixel_of(const Ray& ray) const;

    bool ortho_ = false;
    Vec3 origin_{0.0}, right_{1, 0, 0}, up_{0, 1, 0}, forward_{0, 0, -1};
    double pixel_ = 1.0, half_width_ = 0.0, half_height_ = 0.0;
    int cells_x_ = 0, cells_y_ = 0;
    std::vector<Mark> marks_;
    std::vector<std::vector<uint32_t>> cells_;  // marks touching each cell of kCell x kCell pixels
};

}  // namespace vr
