// An equirectangular environment image as the sky light's radiance (docs/rendering.md, Soft light
// with error bounds, --sky FILE) and as the background where the scene binds no Background node.
//
// Mapping, world axes (not the viewpoint's): +Y is the zenith, the image's top row; the image's
// middle column looks along -Z (the default VRML view), a quarter to its right along +X, a quarter
// to its left along -X, its left and right edges along +Z. For a unit direction w:
//   u = 0.5 + atan2(w.x, -w.z) / (2 pi)  in [0, 1),   v = acos(w.y) / pi  in [0, 1],
// and texel (i, j) (i from the left, j from the top) has its centre at ((i + 0.5) / W, (j + 0.5) /
// H). Filtering is bilinear between the four nearest texel centres, wrapping around in u and
// clamped at the poles in v, so that every value lies between the map's smallest and largest
// texels.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "image/image.h"

namespace vr {

class SkyMap {
  public:
    // The RGB of `image`; texels that are NaN, infinite or negative become 0 (`fixed` counts them).
    explicit SkyMap(const Image& image);
    int width() const { return width_; }
    int height() const { return height_; }
    size_t fixed() const { return fixed_; }
    // Radiance arriving from world direction `dir` (any length; 0 for a zero or non-finite one).
    Vec3 radiance(const Vec3& dir) const;
    Vec3 texel(int i, int j) const;
    // The smallest and largest texel, per channel: radiance() stays within them.
    const Vec3& lowest() const { return lowest_; }
    const Vec3& highest() const { return highest_; }

  private:
    int width_ = 0, height_ = 0;
    size_t fixed_ = 0;
    std::vector<float> rgb_;
    Vec3 lowest_{0.0}, highest_{0.0};
};

// The (u, v) of unit direction `w` (the mapping above).
void sky_map_uv(const Vec3& w, double& u, double& v);

// Reads an image file (.hdr, .exr or any format read_image reads) into `out`; false with `error`
// naming the file when it cannot be read or is empty.
bool load_sky_map(const std::string& path, std::shared_ptr<const SkyMap>& out, std::string& error);

}  // namespace vr
