// Sky light shared between neighbouring pixels (docs/rendering.md, "Sharing the sky light between
// pixels"): A(p) is estimated at the camera hits of a lattice of image points, `spacing` pixels
// apart, to kSharedNodeShare (3/4) of the tolerance; a sample inside a lattice square takes the
// bilinear mean of its four corners' estimates when the corners and the sample lie on one smooth
// surface and the corners' estimates differ by at most the tolerance (a square that holds a
// shadow's edge of its own shows it as a spread). Otherwise the sample is estimated on its own, as
// without sharing. Every corner is computed once, by the first tile that needs it, from its own
// image point alone: the image is the same for every thread count and tile order.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/math.h"

namespace vr {

// The sky light at one lattice point's camera hit.
struct SkyShareNode {
    bool valid = false;    // the camera ray met a lit surface, whose A was estimated
    uint64_t surface = 0;  // which smooth surface (sky_share_surface)
    Vec3 p{0.0};           // the hit, world
    Vec3 p_error{0.0};     // its rounding bound
    Vec3 ng{0.0};          // its geometric normal, facing the camera
    Vec3 ns{0.0};          // its shading normal, facing the camera
    double a = 0.0;        // A(p), to half the tolerance
};

// What counts as one smooth surface: a sphere, a quadric's part (a cylinder's side, its cap), a
// mesh instance, or the triangles of one shading (a mesh, whose neighbouring triangles have other
// indices); the normal and tangent-plane tests of sky_share_interpolate then keep creases and
// folds of a mesh apart. `prim` is the packed reference of render/intersect.h.
uint64_t sky_share_surface(uint32_t prim, uint8_t part, uint32_t shading);

// The lattice points of one tile and its border (a tile's last row and column of points are its
// neighbours' first), copied out of the grid for reading without synchronisation.
struct SkyShareTile {
    int spacing = 0;
    int i0 = 0, j0 = 0;      // the first point's lattice column and row
    int cols = 0, rows = 0;  // points across and down
    std::vector<SkyShareNode> nodes;
};

// A sample at image point (x, y) (pixels, y down) on `surface` at p with shading normal ns: its A
// as the bilinear mean of the lattice corners around it that lie on the sample's surface, with
// shading normals within kSkyShareMinCos of the sample's and of each other, the sample near each
// one's tangent plane (kSkyShareMaxSlope), and estimates that differ by at most `spread`. All four
// corners, or three (a silhouette, a ribbon's edge or a crease crossing the square), their
// bilinear weights then scaled to add up to 1 (so the value lies between their estimates), and
// only where those weights add up to at least kSkyShareMinWeight: the sample well inside the three
// (1/2 measured a 13% higher RMSE on 1tii's centre, bench/README.md, "Three corners at
// silhouettes"). False: estimate the sample on its own.
inline constexpr double kSkyShareMinCos = 0.5;      // 60 degrees between normals at most
inline constexpr double kSkyShareMaxSlope = 0.3;    // height over a corner's plane / distance
inline constexpr double kSkyShareMinWeight = 0.75;  // three corners' share of the weight, least
bool sky_share_interpolate(const SkyShareTile& tile, double x, double y, uint64_t surface,
                           const Vec3& p, const Vec3& ns, double spread, double& a);

// A camera ray's claim on the lattice, set by the tile loop for that ray only: its image point, and
// (filled in at its first hit) the surface it met.
struct SkyShareSample {
    const SkyShareTile* tile = nullptr;
    double x = 0.0, y = 0.0;
    uint64_t surface = 0;
};

// The corners of the lattice square with top-left corner (i, j) of `tile` (bit k: corner k, in
// the order (i, j), (i+1, j), (i, j+1), (i+1, j+1)) whose A may be shared: all four when they are
// valid on one surface with normals within kSkyShareMinCos of each other, else those of every
// three that are; 0 when none are. Only these corners' A is estimated.
unsigned sky_share_square_corners(const SkyShareTile& tile, int i, int j);
// Whether all four corners may share (sky_share_square_corners is 15).
bool sky_share_square_may_share(const SkyShareTile& tile, int i, int j);

// Every lattice point of an image whose A was estimated, each estimated once (lock-free: the first
// tile to claim a point estimates it and publishes it; a tile that finds it claimed but not yet
// published estimates its own copy, the same value, rather than wait).
class SkyShareGrid {
  public:
    SkyShareGrid(int width, int height, int spacing);
    int spacing() const { return spacing_; }
    // Fills `tile` with the points around pixels [x0, x1) x [y0, y1): `hit(x, y)` gives the node of
    // image point (x, y) without its A, `estimate(node)` its A, asked only for the corners of
    // squares that may share.
    template <class Hit, class Estimate>
    void gather(int x0, int y0, int x1, int y1, SkyShareTile& tile, Hit&& hit, Estimate&& estimate);

  private:
    enum : uint8_t { kEmpty = 0, kClaimed = 1, kReady = 2 };
    int spacing_, cols_, rows_;
    std::vector<double> a_;
    std::unique_ptr<std::atomic<uint8_t>[]> state_;
};

template <class Hit, class Estimate>
void SkyShareGrid::gather(int x0, int y0, int x1, int y1, SkyShareTile& tile, Hit&& hit,
                          Estimate&& estimate) {
    tile.spacing = spacing_;
    tile.i0 = x0 / spacing_;
    tile.j0 = y0 / spacing_;
    tile.cols = (x1 + spacing_ - 1) / spacing_ - tile.i0 + 1;
    tile.rows = (y1 + spacing_ - 1) / spacing_ - tile.j0 + 1;
    tile.nodes.resize(size_t(tile.cols) * size_t(tile.rows));
    for (int j = 0; j < tile.rows; ++j)
        for (int i = 0; i < tile.cols; ++i)
            tile.nodes[size_t(j) * size_t(tile.cols) + size_t(i)] =
                hit(double((tile.i0 + i) * spacing_), double((tile.j0 + j) * spacing_));
    thread_local std::vector<uint8_t> wanted;
    wanted.assign(tile.nodes.size(), 0);
    for (int j = 0; j + 1 < tile.rows; ++j)
        for (int i = 0; i + 1 < tile.cols; ++i)
            if (const unsigned corners = sky_share_square_corners(tile, i, j))
                for (int k = 0; k < 4; ++k)
                    if (corners >> k & 1)
                        wanted[size_t(j + k / 2) * size_t(tile.cols) + size_t(i + k % 2)] = 1;
    for (int j = 0; j < tile.rows; ++j) {
        for (int i = 0; i < tile.cols; ++i) {
            const size_t local = size_t(j) * size_t(tile.cols) + size_t(i);
            SkyShareNode& node = tile.nodes[local];
            if (!wanted[local]) {
                node.valid = false;  // never interpolated from
                continue;
            }
            const size_t at = size_t(tile.j0 + j) * size_t(cols_) + size_t(tile.i0 + i);
            std::atomic<uint8_t>& state = state_[at];
            uint8_t seen = state.load(std::memory_order_acquire);
            if (seen == kReady) {
                node.a = a_[at];
                continue;
            }
            node.a = estimate(node);
            if (seen == kEmpty && state.compare_exchange_strong(seen, kClaimed)) {
                a_[at] = node.a;
                state.store(kReady, std::memory_order_release);
            }
        }
    }
}

}  // namespace vr
