#include "render/sky_share.h"

#include <algorithm>
#include <cmath>

#include "render/intersect.h"

namespace vr {

uint64_t sky_share_surface(uint32_t prim, uint8_t part, uint32_t shading) {
    // The top bits keep the three kinds of key apart.
    if (prim_kind(prim) == PrimKind::Triangle) return (uint64_t(1) << 62) | shading;
    return (uint64_t(2) << 62) | (uint64_t(part) << 32) | prim;
}

bool sky_share_interpolate(const SkyShareTile& tile, double x, double y, uint64_t surface,
                           const Vec3& p, const Vec3& ns, double spread, double& a) {
    if (tile.cols < 2 || tile.rows < 2) return false;
    const double fx = x / tile.spacing - tile.i0, fy = y / tile.spacing - tile.j0;
    if (!(fx >= 0.0 && fy >= 0.0)) return false;
    const int ci = std::min(int(fx), tile.cols - 2), cj = std::min(int(fy), tile.rows - 2);
    const double u = fx - ci, v = fy - cj;
    if (!(u <= 1.0 && v <= 1.0)) return false;
    if (!sky_share_square_may_share(tile, ci, cj)) return false;
    const SkyShareNode* corner[4];
    for (int k = 0; k < 4; ++k)
        corner[k] = &tile.nodes[size_t(cj + k / 2) * size_t(tile.cols) + size_t(ci + k % 2)];
    double lo = corner[0]->a, hi = corner[0]->a;
    for (const SkyShareNode* c : corner) {
        // (An invalid corner is also one whose square may not share: its A was not estimated.)
        if (!c->valid || c->surface != surface) return false;
        if (glm::dot(c->ns, ns) < kSkyShareMinCos) return false;
        // The sample on the corner's surface, not across a fold or a gap of it: the chord from the
        // corner keeps near its tangent plane.
        const Vec3 chord = p - c->p;
        if (std::abs(glm::dot(chord, c->ns)) > kSkyShareMaxSlope * glm::length(chord)) return false;
        lo = std::min(lo, c->a);
        hi = std::max(hi, c->a);
    }
    if (!(hi - lo <= spread)) return false;
    a = (1.0 - v) * ((1.0 - u) * corner[0]->a + u * corner[1]->a) +
        v * ((1.0 - u) * corner[2]->a + u * corner[3]->a);
    return true;
}

bool sky_share_square_may_share(const SkyShareTile& tile, int i, int j) {
    const SkyShareNode* corner[4];
    for (int k = 0; k < 4; ++k)
        corner[k] = &tile.nodes[size_t(j + k / 2) * size_t(tile.cols) + size_t(i + k % 2)];
    for (const SkyShareNode* c : corner) {
        if (!c->valid || c->surface != corner[0]->surface) return false;
        for (const SkyShareNode* d : corner)
            if (glm::dot(c->ns, d->ns) < kSkyShareMinCos) return false;
    }
    return true;
}

SkyShareGrid::SkyShareGrid(int width, int height, int spacing)
    : spacing_(std::max(spacing, 1)),
      cols_((std::max(width, 0) + spacing_ - 1) / spacing_ + 1),
      rows_((std::max(height, 0) + spacing_ - 1) / spacing_ + 1),
      a_(size_t(cols_) * size_t(rows_), 0.0),
      state_(new std::atomic<uint8_t>[size_t(cols_) * size_t(rows_)]) {
    for (size_t k = 0; k < size_t(cols_) * size_t(rows_); ++k) state_[k].store(kEmpty);
}

}  // namespace vr
