// The region that a tile's camera rays sweep: the pyramid (pinhole) or prism (orthographic) bounded
// by four planes through the rays at the tile's corners. A box wholly outside one of the planes is
// met by none of the tile's rays, so a tile whose frustum clears every box of the scene's BVH sees
// only background (render/render.cpp skips the BVH for it).
#pragma once
#include <cmath>

#include "core/math.h"

namespace vr {

struct Frustum {
    Vec3 normal[4];  // pointing into the frustum
    Vec3 point[4];   // a point of each plane

    // True when no point of the box [lo, hi] is inside plane k's half-space for some k. The box's
    // vertex farthest along the normal decides; it must lie outside by more than the rounding of
    // the dot product (a few ulps of its terms; 1e-12 relative is far above that), so a box that
    // touches a plane counts as inside.
    bool separates(const double lo[3], const double hi[3]) const {
        for (int k = 0; k < 4; ++k) {
            const Vec3& n = normal[k];
            const Vec3& p = point[k];
            double s = 0.0, scale = 0.0;
            for (int a = 0; a < 3; ++a) {
                const double v = n[a] > 0.0 ? hi[a] : lo[a];
                s += n[a] * (v - p[a]);
                scale += std::fabs(n[a]) * (std::fabs(v) + std::fabs(p[a]));
            }
            if (s < -1e-12 * scale) return true;
        }
        return false;
    }

    // True when the ball of `radius` about `center` lies outside one plane by more than the
    // rounding of the distance (as above): tighter than its box, whose corners reach much farther
    // into the view when the sphere is near and the view wide.
    bool separates_ball(const Vec3& center, double radius) const {
        for (int k = 0; k < 4; ++k) {
            const Vec3& n = normal[k];
            const Vec3 d = center - point[k];
            const double length = glm::length(n);
            const double s = glm::dot(n, d) + radius * length;
            double scale = radius * length;
            for (int a = 0; a < 3; ++a)
                scale += std::fabs(n[a]) * (std::fabs(center[a]) + std::fabs(point[k][a]));
            if (s < -1e-12 * scale) return true;
        }
        return false;
    }
};

}  // namespace vr
