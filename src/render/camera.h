// The camera (docs/manual.md, Camera): VRML conventions, a pinhole or orthographic projection, and
// the pixel sampler chosen for the render.
#pragma once
#include <cmath>
#include <string>

#include "core/math.h"
#include "core/ray.h"
#include "render/flat_scene.h"
#include "render/frustum.h"
#include "render/options.h"
#include "render/sampling.h"

namespace vr {

struct Camera {
    bool ortho = false;
    Vec3 position{0.0, 0.0, 10.0};  // world
    Mat3 world_from_camera{1.0};    // columns: right (+x), up (+y), backward (+z); looks along -z
    double field_of_view = kPi / 4.0;  // perspective: angle across the smaller image dimension
    double ortho_size = 2.0;           // ortho: world extent across the smaller image dimension
    Vec2 ortho_center{0.0};            // ortho: window centre in camera (x, y)
    PixelSampler sampler;
    // Thin lens (docs/rendering.md, Soft light with error bounds): radius in scene units (0: a
    // pinhole) and the distance of the plane in focus along the view.
    double lens_radius = 0.0;
    double focus_distance = 1.0;
    uint64_t lens_seed = 0;
    // The scene has no Viewpoint: the camera looks along -Z from the VRML default orientation and
    // fieldOfView, moved back to frame the scene's bounds as --fit does (docs/manual.md, Camera).
    bool framed_default = false;
    // --orbit: the point looked at and the axis turned about (with the position, the --position,
    // --look-at and --up that give this camera).
    Vec3 orbit_centre{0.0}, orbit_axis{0.0};

    Vec3 forward() const { return glm::normalize(-world_from_camera[2]); }

    // The ray through image point (x, y) in pixel units of a width x height image: x from the left,
    // y from the top, so pixel (i, j) has its centre at (i + 0.5, j + 0.5). Unit direction.
    Ray ray(double x, double y, int width, int height) const;
};

// Camera::ray with the per-image constants computed once, for the render loop.
class CameraRays {
  public:
    CameraRays(const Camera& camera, int width, int height);
    Ray operator()(double x, double y) const {
        const double cx = (x - half_width_) * pixel_, cy = (half_height_ - y) * pixel_;
        Ray r;
        if (ortho_) {
            r.o = origin_ + cx * right_ + cy * up_;
            r.d = forward_;
        } else {
            r.o = origin_;
            r.d = glm::normalize(cx * right_ + cy * up_ + forward_);
        }
        r.t_max = kInf;
        if (lens_radius_ > 0.0) through_lens(r, x, y);
        return r;
    }
    // The frustum of every ray this camera makes through image points in [x0, x1] x [y0, y1];
    // false with a lens (its rays do not share a pyramid) or a view too degenerate to bound.
    bool frustum(double x0, double y0, double x1, double y1, Frustum& f) const;

  private:
    // Moves the ray's origin to a point of the lens chosen by a hash of (x, y) and aims it at the
    // point where the pinhole ray meets the plane in focus: each sample point of every sampler
    // gets its own lens position, so samples spread over pixel and lens together.
    void through_lens(Ray& r, double x, double y) const;
    double lens_radius_ = 0.0, focus_distance_ = 1.0;
    uint64_t lens_seed_ = 0;
    bool ortho_;
    Vec3 origin_, right_, up_, forward_;
    double pixel_, half_width_, half_height_;
};

// Chooses the camera: options.viewpoint (DEF name or description; error if not found), else the
// first viewpoint, else the VRML default (orientation, fov pi/4) framing the scene as with --fit
// (position 0 0 10 when there is nothing to frame). options.fit moves the camera
// along its view direction so the bounds of the scene fill the view; options.camera forces
// perspective or ortho (for ortho from a perspective viewpoint: extent = the view's size at the
// distance of the scene centre). Also validates the sampler options. Returns false and sets `error`
// on failure.
bool make_camera(const FlatScene& scene, const RenderOptions& options, Camera& camera,
                 std::string& error);
// Which camera make_camera chose, for info and the render's note: "Viewpoint DEF Cam \"Front\" at
// (0 1 5)" or "no Viewpoint: framed from +Z at (0 0 12.3), fieldOfView 0.785398".
std::string describe_camera(const FlatScene& scene, const RenderOptions& options,
                            const Camera& camera);

}  // namespace vr
