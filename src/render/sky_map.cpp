#include "render/sky_map.h"

#include <algorithm>
#include <cmath>

namespace vr {

SkyMap::SkyMap(const Image& image) : width_(image.width), height_(image.height) {
    const size_t count = size_t(std::max(width_, 0)) * size_t(std::max(height_, 0));
    rgb_.resize(count * 3);
    lowest_ = Vec3(kInf);
    highest_ = Vec3(0.0);
    for (size_t i = 0; i < count; ++i) {
        for (int c = 0; c < 3; ++c) {
            float v = image.rgba[i * 4 + size_t(c)];
            if (!(v >= 0.0f) || !std::isfinite(v)) {
                v = 0.0f;
                ++fixed_;
            }
            rgb_[i * 3 + size_t(c)] = v;
            lowest_[c] = std::min(lowest_[c], double(v));
            highest_[c] = std::max(highest_[c], double(v));
        }
    }
    if (count == 0) lowest_ = Vec3(0.0);
}

Vec3 SkyMap::texel(int i, int j) const {
    const float* t = rgb_.data() + (size_t(j) * size_t(width_) + size_t(i)) * 3;
    return Vec3(t[0], t[1], t[2]);
}

void sky_map_uv(const Vec3& w, double& u, double& v) {
    u = 0.5 + std::atan2(w.x, -w.z) / (2.0 * kPi);
    if (!(u < 1.0)) u = 0.0;  // atan2 = pi exactly: the seam
    v = std::acos(std::clamp(w.y, -1.0, 1.0)) / kPi;
}

Vec3 SkyMap::radiance(const Vec3& dir) const {
    const double len = glm::length(dir);
    if (rgb_.empty() || !(len > 0.0) || !std::isfinite(len)) return Vec3(0.0);
    double u, v;
    sky_map_uv(dir / len, u, v);
    // Continuous texel coordinates whose integers are texel centres.
    const double x = u * width_ - 0.5, y = std::clamp(v * height_ - 0.5, 0.0, height_ - 1.0);
    const double x0 = std::floor(x), y0 = std::floor(y);
    const double fx = x - x0, fy = y - y0;
    auto wrap = [&](double i) { return int((long long)(i) % width_ + width_) % width_; };
    const int i0 = wrap(x0), i1 = wrap(x0 + 1.0);
    const int j0 = int(y0), j1 = std::min(j0 + 1, height_ - 1);
    return (1.0 - fy) * ((1.0 - fx) * texel(i0, j0) + fx * texel(i1, j0)) +
           fy * ((1.0 - fx) * texel(i0, j1) + fx * texel(i1, j1));
}

bool load_sky_map(const std::string& path, std::shared_ptr<const SkyMap>& out, std::string& error) {
    Image image;
    if (!read_image(path, image, error)) return false;
    if (image.width <= 0 || image.height <= 0) {
        error = "sky image '" + path + "' has no pixels";
        return false;
    }
    out = std::make_shared<const SkyMap>(image);
    return true;
}

}  // namespace vr
