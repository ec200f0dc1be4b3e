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

namespace {

// Whether corners a and b may share: both met a lit surface, the same one, with shading normals
// within kSkyShareMinCos.
bool corners_agree(const SkyShareNode& a, const SkyShareNode& b) {
    return a.valid && b.valid && a.surface == b.surface && glm::dot(a.ns, b.ns) >= kSkyShareMinCos;
}

// Whether the corners in `mask` (bit k: corner k) pairwise agree.
bool mask_agrees(const SkyShareNode* const (&corner)[4], unsigned mask) {
    for (int k = 0; k < 4; ++k)
        for (int l = k; l < 4; ++l)
            if ((mask >> k & 1) && (mask >> l & 1) && !corners_agree(*corner[k], *corner[l]))
                return false;
    return true;
}

void square_corners(const SkyShareTile& tile, int i, int j, const SkyShareNode* (&corner)[4]) {
    for (int k = 0; k < 4; ++k)
        corner[k] = &tile.nodes[size_t(j + k / 2) * size_t(tile.cols) + size_t(i + k % 2)];
}

}  // namespace

bool sky_share_interpolate(const SkyShareTile& tile, double x, double y, uint64_t surface,
                           const Vec3& p, const Vec3& ns, double spread, double& a) {
    if (tile.cols < 2 || tile.rows < 2) return false;
    const double fx = x / tile.spacing - tile.i0, fy = y / tile.spacing - tile.j0;
    if (!(fx >= 0.0 && fy >= 0.0)) return false;
    const int ci = std::min(int(fx), tile.cols - 2), cj = std::min(int(fy), tile.rows - 2);
    const double u = fx - ci, v = fy - cj;
    if (!(u <= 1.0 && v <= 1.0)) return false;
    const unsigned estimated = sky_share_square_corners(tile, ci, cj);
    if (estimated == 0) return false;
    const SkyShareNode* corner[4];
    square_corners(tile, ci, cj, corner);
    const double weight[4] = {(1.0 - u) * (1.0 - v), u * (1.0 - v), (1.0 - u) * v, u * v};
    unsigned used = 0;
    for (int k = 0; k < 4; ++k) {
        const SkyShareNode* c = corner[k];
        // (A corner that was not estimated is invalid here: see SkyShareGrid::gather.)
        if (!(estimated >> k & 1) || !c->valid || c->surface != surface) continue;
        if (glm::dot(c->ns, ns) < kSkyShareMinCos) continue;
        // The sample on the corner's surface, not across a fold or a gap of it: the chord from the
        // corner keeps near its tangent plane.
        const Vec3 chord = p - c->p;
        if (std::abs(glm::dot(chord, c->ns)) > kSkyShareMaxSlope * glm::length(chord)) continue;
        used |= 1u << k;
    }
    // Four corners, or three at a silhouette or a crease that crosses the square, where the sample
    // lies well inside them (kSkyShareMinWeight).
    if (__builtin_popcount(used) < 3) return false;
    if (!mask_agrees(corner, used)) {
        // Four corners across a crease: the three that agree, leaving out the farthest possible.
        if (used != 15) return false;
        int best = -1;
        for (int out = 0; out < 4; ++out)
            if (mask_agrees(corner, 15u & ~(1u << out)) && (best < 0 || weight[out] < weight[best]))
                best = out;
        if (best < 0) return false;
        used = 15u & ~(1u << best);
    }
    double lo = 1.0, hi = 0.0, sum = 0.0, weights = 0.0;
    for (int k = 0; k < 4; ++k) {
        if (!(used >> k & 1)) continue;
        lo = std::min(lo, corner[k]->a);
        hi = std::max(hi, corner[k]->a);
        sum += weight[k] * corner[k]->a;
        weights += weight[k];
    }
    if (!(weights >= kSkyShareMinWeight)) return false;
    if (!(hi - lo <= spread)) return false;
    a = used == 15 ? sum : sum / weights;  // four corners: the bilinear mean, exactly as before
    return true;
}

unsigned sky_share_square_corners(const SkyShareTile& tile, int i, int j) {
    const SkyShareNode* corner[4];
    square_corners(tile, i, j, corner);
    if (mask_agrees(corner, 15)) return 15;
    // The triples (all corners but one) that agree.
    unsigned mask = 0;
    for (int out = 0; out < 4; ++out) {
        const unsigned triple = 15u & ~(1u << out);
        if (mask_agrees(corner, triple)) mask |= triple;
    }
    return mask;
}

bool sky_share_square_may_share(const SkyShareTile& tile, int i, int j) {
    return sky_share_square_corners(tile, i, j) == 15;
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
