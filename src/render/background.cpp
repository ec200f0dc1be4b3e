#include "render/background.h"

#include <algorithm>
#include <cmath>

#include "render/shading.h"

namespace vr {
namespace {

// Colour at `angle` along a ramp: colors[0] at 0, colors[i+1] at angles[i], linear in between, the
// last colour beyond the last angle.
Vec3 ramp(const std::vector<Vec3>& colors, const std::vector<double>& angles, double angle) {
    if (colors.empty()) return Vec3(0.0);
    size_t n = std::min(colors.size() - 1, angles.size());
    double prev_angle = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double a = angles[i];
        if (angle <= a) {
            double span = a - prev_angle;
            double f = span > 0.0 ? (angle - prev_angle) / span : 1.0;
            f = std::clamp(f, 0.0, 1.0);
            return colors[i] + f * (colors[i + 1] - colors[i]);
        }
        prev_angle = a;
    }
    return colors[n];
}

}  // namespace

BackgroundModel::BackgroundModel(const FlatScene& scene, const std::optional<Vec3>& override_color,
                                 const SkyMap* sky_map)
    : scene_(scene), constant_(override_color) {
    const Background& bg = scene.background;
    if (!constant_ && !bg.present && sky_map) {
        sky_map_ = sky_map;
        return;
    }
    bool panorama = false;
    for (int32_t t : bg.panorama) panorama = panorama || t >= 0;
    if (!constant_ && bg.sky_colors.size() <= 1 &&
        (bg.ground_colors.empty() || bg.ground_angles.empty()) && !panorama)
        constant_ = bg.sky_colors.empty() ? Vec3(0.0) : bg.sky_colors[0];
    const Mat3& m = scene.background.world_from_background;
    double det = glm::determinant(m);
    if (std::isfinite(det) && det != 0.0) background_from_world_ = glm::inverse(m);
}

Vec3 BackgroundModel::gradient(const Vec3& v) const {
    const Background& bg = scene_.background;
    const double zenith_angle = std::acos(std::clamp(v.y, -1.0, 1.0));
    const double nadir_angle = kPi - zenith_angle;
    // VRML97 6.5: the ground runs from the nadir to the last groundAngle and does not exist beyond
    // it, so without a groundAngle there is no ground and the sky shows below the horizon
    // (docs/rendering.md, Background). One colour with angles: that colour up to the first angle.
    if (!bg.ground_colors.empty() && !bg.ground_angles.empty()) {
        const size_t last =
            std::min(bg.ground_angles.size(), std::max<size_t>(bg.ground_colors.size() - 1, 1));
        if (nadir_angle <= bg.ground_angles[last - 1])
            return ramp(bg.ground_colors, bg.ground_angles, nadir_angle);
    }
    return ramp(bg.sky_colors, bg.sky_angles, zenith_angle);
}

Vec3 BackgroundModel::radiance(const Vec3& dir) const {
    if (constant_) return *constant_;
    if (sky_map_) return sky_map_->radiance(dir);
    const Background& bg = scene_.background;
    Vec3 v = background_from_world_ * dir;
    double len = glm::length(v);
    if (!(len > 0.0) || !std::isfinite(len)) return Vec3(0.0);
    v /= len;
    Vec3 color = gradient(v);

    // Panorama: the cube face the direction points at (front -z, back +z, left -x, right +x, top
    // +y, bottom -y), each image upright as seen from the centre (VRML97 6.5).
    const Vec3 a = glm::abs(v);
    int face;
    double s, t;
    if (a.z >= a.x && a.z >= a.y) {
        double x = v.x / a.z, y = v.y / a.z;
        face = v.z < 0.0 ? 0 : 1;
        s = v.z < 0.0 ? 0.5 * (x + 1.0) : 0.5 * (1.0 - x);
        t = 0.5 * (y + 1.0);
    } else if (a.x >= a.y) {
        double z = v.z / a.x, y = v.y / a.x;
        face = v.x < 0.0 ? 2 : 3;
        s = v.x < 0.0 ? 0.5 * (1.0 - z) : 0.5 * (z + 1.0);
        t = 0.5 * (y + 1.0);
    } else {
        double x = v.x / a.y, z = v.z / a.y;
        face = v.y > 0.0 ? 4 : 5;
        s = 0.5 * (x + 1.0);
        t = v.y > 0.0 ? 0.5 * (z + 1.0) : 0.5 * (1.0 - z);
    }
    int32_t tex = bg.panorama[face];
    if (tex >= 0 && size_t(tex) < scene_.textures.size()) {
        const Texture& texture = scene_.textures[size_t(tex)];
        TexelValue tv = sample_texture(texture, Vec2(s, t), /*clamp=*/true);
        double alpha = std::clamp(tv.a, 0.0, 1.0);
        color = alpha * tv.rgb + (1.0 - alpha) * color;
    }
    return color;
}

double fog_factor(const Fog& fog, double d) {
    const double range = fog.visibility_range;
    if (fog.kind == FogKind::None || !(range > 0.0) || !std::isfinite(range)) return 1.0;
    if (!(d < range)) return 0.0;
    if (fog.kind == FogKind::Linear) return std::clamp((range - d) / range, 0.0, 1.0);
    return std::exp(-d / (range - d));
}

double fog_coordinate_factor(double depth) {
    return std::isfinite(depth) ? 1.0 - std::clamp(depth, 0.0, 1.0) : 1.0;
}

}  // namespace vr
