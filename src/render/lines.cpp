#include "render/lines.h"

#include <algorithm>
#include <cmath>

namespace vr {

namespace {
constexpr int kCell = 16;  // pixels a grid cell: a few marks per cell for typical wireframes
}

LineOverlay::LineOverlay(const FlatScene& scene, const Camera& camera, int width, int height,
                         double line_width, double point_size)
    : ortho_(camera.ortho),
      right_(camera.world_from_camera[0]),
      up_(camera.world_from_camera[1]),
      forward_(glm::normalize(-camera.world_from_camera[2])),
      half_width_(0.5 * width),
      half_height_(0.5 * height) {
    if (scene.segments.empty() && scene.points.empty()) return;
    // The same image plane as CameraRays: one pixel is `pixel_` wide at unit depth (perspective)
    // or in world units (ortho).
    const double smaller = double(std::min(width, height));
    if (ortho_) {
        pixel_ = camera.ortho_size / smaller;
        origin_ = camera.position + camera.world_from_camera * Vec3(camera.ortho_center, 0.0);
    } else {
        pixel_ = 2.0 * std::tan(0.5 * camera.field_of_view) / smaller;
        origin_ = camera.position;
    }
    cells_x_ = (width + kCell - 1) / kCell;
    cells_y_ = (height + kCell - 1) / kCell;
    cells_.resize(size_t(cells_x_) * size_t(cells_y_));
    for (const LineSegment& s : scene.segments) {
        Vec3 a = s.a, b = s.b, ca = s.color_a, cb = s.color_b;
        double aa = s.alpha_a, ab = s.alpha_b;
        if (!ortho_) {
            // Clip to the part in front of the camera (depth > a millionth of the far end's).
            const double da = glm::dot(a - origin_, forward_), db = glm::dot(b - origin_, forward_);
            const double near = 1e-6 * std::max(da, db);
            if (!(near > 0.0)) continue;
            auto clip = [&](Vec3& p, Vec3& c, double& o, double dp, const Vec3& q, const Vec3& cq,
                            double oq, double dq) {
                if (dp >= near) return;
                const double u = (near - dp) / (dq - dp);
                p = p + u * (q - p);
                c = c + u * (cq - c);
                o = o + u * (oq - o);
            };
            clip(a, ca, aa, da, b, cb, ab, db);
            clip(b, cb, ab, db, s.a, s.color_a, s.alpha_a, da);
        }
        Mark m;
        if (!project(a, m.a, m.za) || !project(b, m.b, m.zb)) continue;
        m.pa = a, m.pb = b, m.ca = ca, m.cb = cb, m.aa = aa, m.ab = ab;
        m.radius = 0.5 * line_width;
        add(m);
    }
    for (const PointMark& p : scene.points) {
        Mark m;
        if (!project(p.position, m.a, m.za)) continue;
        m.b = m.a, m.zb = m.za, m.pa = m.pb = p.position, m.ca = m.cb = p.color;
        m.aa = m.ab = p.alpha;
        m.radius = 0.5 * point_size;
        add(m);
    }
}

bool LineOverlay::project(const Vec3& world, Vec2& pixel, double& depth) const {
    const Vec3 v = world - origin_;
    const double z = glm::dot(v, forward_);
    if (!ortho_ && !(z > 0.0)) return false;
    const double scale = ortho_ ? 1.0 : 1.0 / z;
    pixel = Vec2(glm::dot(v, right_) * scale / pixel_ + half_width_,
                 half_height_ - glm::dot(v, up_) * scale / pixel_);
    depth = ortho_ ? 1.0 : z;
    return std::isfinite(pixel.x) && std::isfinite(pixel.y);
}

void LineOverlay::add(const Mark& m) {
    const double r = m.radius + 1.0;  // a pixel of margin for the cell lookup's rounding
    const int x0 = std::max(0, int(std::floor((std::min(m.a.x, m.b.x) - r) / kCell)));
    const int y0 = std::max(0, int(std::floor((std::min(m.a.y, m.b.y) - r) / kCell)));
    const int x1 = std::min(cells_x_ - 1, int(std::floor((std::max(m.a.x, m.b.x) + r) / kCell)));
    const int y1 = std::min(cells_y_ - 1, int(std::floor((std::max(m.a.y, m.b.y) + r) / kCell)));
    if (x0 > x1 || y0 > y1) return;  // off the image
    const uint32_t index = uint32_t(marks_.size());
    marks_.push_back(m);
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
            cells_[size_t(y) * size_t(cells_x_) + size_t(x)].push_back(index);
}

Vec2 LineOverlay::pixel_of(const Ray& ray) const {
    if (ortho_) {
        const Vec3 v = ray.o - origin_;
        return Vec2(glm::dot(v, right_) / pixel_ + half_width_,
                    half_height_ - glm::dot(v, up_) / pixel_);
    }
    const double z = glm::dot(ray.d, forward_);
    return Vec2(glm::dot(ray.d, right_) / (z * pixel_) + half_width_,
                half_height_ - glm::dot(ray.d, up_) / (z * pixel_));
}

bool LineOverlay::nearest(const Ray& ray, double t_surface, Vec3& color, double& alpha) const {
    if (marks_.empty()) return false;
    const Vec2 q = pixel_of(ray);
    const int cx = int(std::floor(q.x / kCell)), cy = int(std::floor(q.y / kCell));
    if (!(cx >= 0 && cy >= 0 && cx < cells_x_ && cy < cells_y_)) return false;
    double best = kInf;
    for (uint32_t index : cells_[size_t(cy) * size_t(cells_x_) + size_t(cx)]) {
        const Mark& m = marks_[index];
        const Vec2 ab = m.b - m.a;
        const double len2 = glm::dot(ab, ab);
        const double s = len2 > 0.0 ? std::clamp(glm::dot(q - m.a, ab) / len2, 0.0, 1.0) : 0.0;
        const Vec2 closest = m.a + s * ab;
        if (glm::dot(q - closest, q - closest) > m.radius * m.radius) continue;
        // 1/depth is linear on the screen: the world parameter of screen parameter s.
        const double u = ortho_ || m.za == m.zb ? s : s * m.za / (s * m.za + (1.0 - s) * m.zb);
        const Vec3 p = m.pa + u * (m.pb - m.pa);
        const double t = glm::dot(p - ray.o, ray.d);
        if (!(t >= 0.0)) continue;  // behind an orthographic camera's image plane
        // One line width of depth at the mark: a line on a face is in front of it.
        const double slack = 2.0 * m.radius * pixel_ * (ortho_ ? 1.0 : std::max(t, 0.0));
        if (!(t <= t_surface + slack) || !(t < best)) continue;
        best = t;
        color = m.ca + u * (m.cb - m.ca);
        alpha = m.aa + u * (m.ab - m.aa);
    }
    return best < kInf;
}

}  // namespace vr
