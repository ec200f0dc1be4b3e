#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/format.h"

namespace vr {
namespace {

bool finite3(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// An orthonormal right-handed basis from the viewpoint's (possibly sloppy) rotation.
Mat3 orthonormal(const Mat3& m) {
    Vec3 back = m[2], up = m[1];
    if (!finite3(back) || glm::dot(back, back) == 0.0) back = Vec3(0.0, 0.0, 1.0);
    back = glm::normalize(back);
    Vec3 right = glm::cross(up, back);
    if (!finite3(right) || glm::dot(right, right) == 0.0) {
        // Up parallel to the view: any perpendicular will do.
        right =
            glm::cross(std::fabs(back.y) < 0.9 ? Vec3(0.0, 1.0, 0.0) : Vec3(1.0, 0.0, 0.0), back);
    }
    right = glm::normalize(right);
    up = glm::cross(back, right);
    return Mat3(right, up, back);
}

// Distance from the scene's bounding-box centre at which a perspective camera looking along
// `forward` sees all eight corners of the box.
double fit_distance(const Bounds3& b, const Camera& cam, double tan_x, double tan_y) {
    const Vec3 c = 0.5 * (b.lo + b.hi);
    const Vec3 right = cam.world_from_camera[0], up = cam.world_from_camera[1], fwd = cam.forward();
    double d = 0.0;
    for (int i = 0; i < 8; ++i) {
        Vec3 corner((i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y,
                    (i & 4) ? b.hi.z : b.lo.z);
        Vec3 q = corner - c;
        double qx = std::fabs(glm::dot(q, right)), qy = std::fabs(glm::dot(q, up)),
               qf = glm::dot(q, fwd);
        d = std::max(d, qx / tan_x - qf);
        d = std::max(d, qy / tan_y - qf);
    }
    return d;
}

// The basis of a camera at `from` looking at `to` with `up` shown upwards (the viewpoint's up
// when `up` is parallel to the view). False when from == to.
bool look_at_basis(const Vec3& from, const Vec3& to, const Vec3& up, Mat3& basis) {
    const Vec3 back = from - to;
    if (!(glm::dot(back, back) > 0.0) || !finite3(back)) return false;
    basis = orthonormal(Mat3(Vec3(0.0), up, back));
    return true;
}

// --position, --look-at, --up and --fov on the viewpoint's camera.
bool apply_overrides(const RenderOptions& options, Camera& camera, std::string& error) {
    if (options.fov) {
        if (!(*options.fov > 0.0 && *options.fov < kPi)) {
            error = "--fov must lie in (0, pi) radians, got " + format_g(*options.fov);
            return false;
        }
        camera.field_of_view = *options.fov;
    }
    for (const auto& [v, name] :
         {std::pair{&options.camera_position, "--position"},
          std::pair{&options.look_at, "--look-at"}, std::pair{&options.up, "--up"}})
        if (*v && !finite3(**v)) {
            error = std::string(name) + " must be three finite numbers";
            return false;
        }
    if (options.up && !(glm::dot(*options.up, *options.up) > 0.0)) {
        error = "--up must not be 0,0,0";
        return false;
    }
    if (options.camera_position) camera.position = *options.camera_position;
    const Vec3 up = options.up ? *options.up : camera.world_from_camera[1];
    if (options.look_at) {
        if (!look_at_basis(camera.position, *options.look_at, up, camera.world_from_camera)) {
            error = "--look-at is the camera position itself: no direction to look in";
            return false;
        }
    } else if (options.up) {
        camera.world_from_camera = orthonormal(Mat3(Vec3(0.0), up, camera.world_from_camera[2]));
    }
    return true;
}

// --orbit: the camera turned by `angle` about `centre` around its up axis, looking at the centre
// with that axis up. Rodrigues' rotation of the offset, so that angle 0 keeps it as it is.
void orbit_camera(const Vec3& centre, double angle, Camera& camera) {
    const Vec3 axis = glm::normalize(camera.world_from_camera[1]);
    const Vec3 offset = camera.position - centre;
    const double c = std::cos(angle), s = std::sin(angle);
    const Vec3 turned =
        offset * c + glm::cross(axis, offset) * s + axis * (glm::dot(axis, offset) * (1.0 - c));
    camera.position = centre + turned;
    camera.orbit_centre = centre;
    camera.orbit_axis = axis;
    Mat3 basis;
    if (look_at_basis(camera.position, centre, axis, basis)) camera.world_from_camera = basis;
}

}  // namespace

CameraRays::CameraRays(const Camera& c, int width, int height)
    : lens_radius_(c.lens_radius),
      focus_distance_(c.focus_distance),
      lens_seed_(c.lens_seed),
      ortho_(c.ortho),
      right_(c.world_from_camera[0]),
      up_(c.world_from_camera[1]),
      forward_(-c.world_from_camera[2]),
      half_width_(0.5 * width),
      half_height_(0.5 * height) {
    const double smaller = double(width < height ? width : height);
    if (ortho_) {
        pixel_ = c.ortho_size / smaller;
        origin_ = c.position + c.world_from_camera * Vec3(c.ortho_center, 0.0);
        forward_ = glm::normalize(forward_);
    } else {
        pixel_ = 2.0 * std::tan(0.5 * c.field_of_view) / smaller;
        origin_ = c.position;
    }
}

bool CameraRays::frustum(double x0, double y0, double x1, double y1, Frustum& f) const {
    if (lens_radius_ > 0.0) return false;
    // Corners in order around the rectangle; each plane holds the rays of one edge.
    const Ray corner[4] = {(*this)(x0, y0), (*this)(x1, y0), (*this)(x1, y1), (*this)(x0, y1)};
    const Ray middle = (*this)(0.5 * (x0 + x1), 0.5 * (y0 + y1));
    for (int k = 0; k < 4; ++k) {
        const Ray& a = corner[k];
        const Ray& b = corner[(k + 1) % 4];
        // Pinhole: the plane through the common origin holding both directions; orthographic:
        // the plane holding the shared direction and the segment between the two origins.
        Vec3 n = ortho_ ? glm::cross(a.d, b.o - a.o) : glm::cross(a.d, b.d);
        const double inward = glm::dot(n, middle.o + middle.d - a.o);
        if (!(std::fabs(inward) > 0.0) || !std::isfinite(inward)) return false;
        f.normal[k] = inward > 0.0 ? n : -n;
        f.point[k] = a.o;
    }
    return true;
}

void CameraRays::through_lens(Ray& r, double x, double y) const {
    uint64_t bx, by;
    std::memcpy(&bx, &x, sizeof bx);
    std::memcpy(&by, &y, sizeof by);
    const uint64_t key = sample_hash(lens_seed_ ^ 0x1e25, int(by), int(by >> 32), bx);
    // Shirley and Chiu's concentric map of the square onto the disc keeps strata compact.
    const double a = 2.0 * sample_uniform(key, 0, 0, 0) - 1.0;
    const double b = 2.0 * sample_uniform(key, 0, 0, 1) - 1.0;
    double radius = 0.0, phi = 0.0;
    if (a != 0.0 || b != 0.0) {
        if (std::abs(a) > std::abs(b)) {
            radius = a;
            phi = 0.25 * kPi * (b / a);
        } else {
            radius = b;
            phi = 0.5 * kPi - 0.25 * kPi * (a / b);
        }
    }
    const double along = glm::dot(r.d, forward_);
    const Vec3 focus = r.o + (focus_distance_ / along) * r.d;
    r.o += lens_radius_ * radius * (std::cos(phi) * right_ + std::sin(phi) * up_);
    r.d = glm::normalize(focus - r.o);
}

Ray Camera::ray(double x, double y, int width, int height) const {
    return CameraRays(*this, width, height)(x, y);
}

namespace {

// The viewpoint the camera starts from: --viewpoint's (false, with `error`, when the scene has
// none of that name), else the scene's first, else the VRML default, which the camera then frames.
bool choose_viewpoint(const FlatScene& scene, const RenderOptions& options, Camera& camera,
                      Viewpoint& vp, std::string& error) {
    bool found = false;
    if (!options.viewpoint.empty()) {
        for (const Viewpoint& v : scene.viewpoints) {
            if (v.def_name == options.viewpoint || v.description == options.viewpoint) {
                vp = v;
                found = true;
                break;
            }
        }
        if (!found) {
            error = "no viewpoint named '" + options.viewpoint + "'";
            if (!scene.viewpoints.empty()) {
                error += " (the scene has:";
                for (const Viewpoint& v : scene.viewpoints) {
                    std::string name = !v.def_name.empty() ? v.def_name : v.description;
                    error += " '" + name + "'";
                }
                error += ")";
            }
            return false;
        }
    } else if (!scene.viewpoints.empty()) {
        vp = scene.viewpoints.front();
    } else {
        camera.framed_default = true;
    }

    return true;
}

// --fit, or a default view: the camera moved back along its view (an orthographic one's window
// widened) until the scene's bounds are in the picture.
void frame_bounds(const Bounds3& bounds, const Vec3& centre, const RenderOptions& options,
                  Camera& camera) {
    const double smaller = std::min(options.width, options.height);
    const Vec3 fwd = camera.forward();
    const double radius = 0.5 * glm::length(bounds.hi - bounds.lo);
    if (camera.ortho) {
        const Vec3 right = camera.world_from_camera[0], up = camera.world_from_camera[1];
        double max_x = 0.0, max_y = 0.0;
        for (int i = 0; i < 8; ++i) {
            Vec3 corner((i & 1) ? bounds.hi.x : bounds.lo.x, (i & 2) ? bounds.hi.y : bounds.lo.y,
                        (i & 4) ? bounds.hi.z : bounds.lo.z);
            max_x = std::max(max_x, std::fabs(glm::dot(corner - centre, right)));
            max_y = std::max(max_y, std::fabs(glm::dot(corner - centre, up)));
        }
        double pixel = std::max(2.0 * max_x / options.width, 2.0 * max_y / options.height);
        if (pixel > 0.0) camera.ortho_size = pixel * smaller;
        camera.ortho_center = Vec2(0.0);
        // Start the rays outside the scene.
        camera.position = centre - fwd * (2.0 * radius);
    } else {
        const double t = std::tan(0.5 * camera.field_of_view);
        const double tan_x = t * options.width / smaller, tan_y = t * options.height / smaller;
        double d = fit_distance(bounds, camera, tan_x, tan_y);
        if (d > 0.0) camera.position = centre - fwd * d;
    }
}

}  // namespace

bool make_camera(const FlatScene& scene, const RenderOptions& options, Camera& camera,
                 std::string& error) {
    if (options.width < 1 || options.height < 1) {
        error = "image size must be at least 1x1 (got " + std::to_string(options.width) + "x" +
                std::to_string(options.height) + ")";
        return false;
    }
    if (!make_sampler(options, camera.sampler, error)) return false;
    if (options.aperture > 0.0 && camera.sampler.kind == SamplerKind::Center) {
        error =
            "--aperture needs several samples per pixel spread over the lens: pick a sampler "
            "(e.g. --sampler jitter --spp 64, or --sampler statistical)";
        return false;
    }
    if (!(options.aperture >= 0.0) || !std::isfinite(options.aperture) || !(options.focus >= 0.0) ||
        !std::isfinite(options.focus)) {
        error = "--aperture and --focus must be finite and not negative";
        return false;
    }
    camera.lens_radius = options.aperture;
    camera.lens_seed = options.seed;

    Viewpoint vp;  // the VRML default
    if (!choose_viewpoint(scene, options, camera, vp, error)) return false;

    if (!finite3(vp.position)) {
        error = "viewpoint position is not finite";
        return false;
    }
    camera.position = vp.position;
    camera.world_from_camera = orthonormal(vp.world_from_camera);
    camera.ortho = vp.ortho;
    if (vp.ortho) {
        const double* e = vp.ortho_extent;
        double w = e[2] - e[0], h = e[3] - e[1];
        if (!(w > 0.0) || !(h > 0.0) || !std::isfinite(w) || !std::isfinite(h)) {
            error = "OrthoViewpoint fieldOfView must give min < max in both directions";
            return false;
        }
        camera.ortho_size = options.width <= options.height ? w : h;
        camera.ortho_center = Vec2(0.5 * (e[0] + e[2]), 0.5 * (e[1] + e[3]));
    } else {
        if (!(vp.field_of_view > 0.0 && vp.field_of_view < kPi)) {
            error = "viewpoint fieldOfView must lie in (0, pi), got " + format_g(vp.field_of_view);
            return false;
        }
        camera.field_of_view = vp.field_of_view;
    }

    if (!apply_overrides(options, camera, error)) return false;
    // A camera placed by --position is where the user put it: no framing of a default view.
    if (options.camera_position) camera.framed_default = false;

    const Bounds3 bounds = scene.bounds(options.threads);
    const bool have_bounds = !bounds.empty();
    const Vec3 centre = have_bounds ? 0.5 * (bounds.lo + bounds.hi) : Vec3(0.0);
    // Distance from the camera to the scene centre along the view, for switching projections.
    double centre_depth = glm::dot(centre - camera.position, camera.forward());
    if (!(centre_depth > 0.0)) centre_depth = glm::length(centre - camera.position);
    if (!(centre_depth > 0.0)) centre_depth = 10.0;  // the VRML default viewing distance

    if (options.camera == CameraMode::Ortho && !camera.ortho) {
        camera.ortho = true;
        camera.ortho_size = 2.0 * centre_depth * std::tan(0.5 * camera.field_of_view);
        camera.ortho_center = Vec2(0.0);
    } else if (options.camera == CameraMode::Perspective && camera.ortho) {
        camera.ortho = false;
        // The same window seen from the camera at the scene centre's depth; the window's offset is
        // lost.
        camera.field_of_view = 2.0 * std::atan(0.5 * camera.ortho_size / centre_depth);
    }

    if ((options.fit || camera.framed_default) && have_bounds)
        frame_bounds(bounds, centre, options, camera);
    if (options.orbit_angle) orbit_camera(centre, *options.orbit_angle, camera);
    // Without --focus the lens focuses on the scene's centre, where the camera now stands.
    const double focus =
        options.focus > 0.0 ? options.focus : glm::dot(centre - camera.position, camera.forward());
    camera.focus_distance = focus > 0.0 && std::isfinite(focus) ? focus : 10.0;
    return true;
}

namespace {

std::string point_text(const Vec3& p) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%g %g %g)", p.x + 0.0, p.y + 0.0, p.z + 0.0);  // + 0: no "-0"
    return buf;
}

}  // namespace

std::string describe_camera(const FlatScene& scene, const RenderOptions& options,
                            const Camera& camera) {
    if (camera.framed_default) {
        if (scene.bounds(options.threads).empty())
            return "no Viewpoint and nothing to frame: the default camera at " +
                   point_text(camera.position);
        char fov[48];
        std::snprintf(fov, sizeof fov, "%g", camera.field_of_view);
        return "no Viewpoint: framed from +Z at " + point_text(camera.position) +
               (camera.ortho ? std::string(", orthographic") : ", fieldOfView " + std::string(fov));
    }
    if (scene.viewpoints.empty()) return "the default camera at " + point_text(camera.position);
    const Viewpoint* vp = &scene.viewpoints.front();
    for (const Viewpoint& v : scene.viewpoints)
        if (!options.viewpoint.empty() &&
            (v.def_name == options.viewpoint || v.description == options.viewpoint)) {
            vp = &v;
            break;
        }
    std::string text = vp->ortho ? "OrthoViewpoint" : "Viewpoint";
    if (!vp->def_name.empty()) text += " DEF " + vp->def_name;
    if (!vp->description.empty()) text += " \"" + vp->description + "\"";
    if (vp->def_name.empty() && vp->description.empty())
        text += " (unnamed, the first in the file)";
    text += " at " + point_text(camera.position);
    if (options.fit) text += " (moved by --fit)";
    return text;
}

}  // namespace vr
