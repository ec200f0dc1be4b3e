#include "render/work_estimate.h"

#include <algorithm>
#include <cmath>

namespace vr {

std::vector<int> trace_order(const std::vector<int>& tiles, int tiles_x, int tiles_y) {
    if (tiles_x <= 0 || tiles_y <= 0) return tiles;
    // Rank of each tile row: its place in the bit-reversed order over the next power of two.
    int bits = 0;
    while ((1 << bits) < tiles_y) ++bits;
    std::vector<int> rank(size_t(tiles_y), 0);
    std::vector<int> rows;
    for (int k = 0; k < (1 << bits); ++k) {
        int r = 0;
        for (int b = 0; b < bits; ++b)
            if (k & (1 << b)) r |= 1 << (bits - 1 - b);
        if (r < tiles_y) rows.push_back(r);
    }
    for (size_t i = 0; i < rows.size(); ++i) rank[size_t(rows[i])] = int(i);
    std::vector<int> order = tiles;
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        const int ra = rank[size_t(std::clamp(a / tiles_x, 0, tiles_y - 1))];
        const int rb = rank[size_t(std::clamp(b / tiles_x, 0, tiles_y - 1))];
        return ra != rb ? ra < rb : a < b;
    });
    return order;
}

TileWorkEstimate::TileWorkEstimate(const std::vector<int>& tiles, int tiles_x, int tiles_y)
    : tiles_x_(std::max(tiles_x, 0)),
      tiles_y_(std::max(tiles_y, 0)),
      tiles_(tiles),
      cells_(new std::atomic<int64_t>[size_t(tiles_x_) * size_t(tiles_y_)]) {
    const size_t n = size_t(tiles_x_) * size_t(tiles_y_);
    for (size_t i = 0; i < n; ++i) cells_[i].store(-1, std::memory_order_relaxed);
    for (int t : tiles_)
        if (t >= 0 && size_t(t) < n) cells_[size_t(t)].store(0, std::memory_order_relaxed);
}

void TileWorkEstimate::record(int tile, uint64_t rays) {
    if (tile < 0 || size_t(tile) >= size_t(tiles_x_) * size_t(tiles_y_)) return;
    cells_[size_t(tile)].store(int64_t(std::min<uint64_t>(rays, INT64_MAX - 1)) + 1,
                               std::memory_order_release);
}

std::vector<double> TileWorkEstimate::all_tiles() const {
    const size_t w = size_t(tiles_x_), h = size_t(tiles_y_);
    std::vector<double> cost(w * h, -1.0);  // -1: not known
    std::vector<double> row_sum(h, 0.0);
    std::vector<int> row_done(h, 0);
    for (size_t i = 0; i < w * h; ++i) {
        const int64_t c = cells_[i].load(std::memory_order_acquire);
        if (c > 0) {
            cost[i] = double(c - 1);
            row_sum[i / w] += cost[i];
            ++row_done[i / w];
        }
    }
    // A tile's known neighbours in its column, else the mean of a traced row.
    auto known = [&](size_t x, size_t y) {
        if (cost[y * w + x] >= 0.0) return cost[y * w + x];
        return row_done[y] > 0 ? row_sum[y] / row_done[y] : -1.0;
    };
    // Per column: sweeps down and up carry the nearest known value above and below each tile.
    std::vector<double> out(w * h, 0.0), above(h), below(h);
    std::vector<size_t> above_row(h), below_row(h);
    for (size_t x = 0; x < w; ++x) {
        double last = -1.0;
        size_t last_row = 0;
        for (size_t y = 0; y < h; ++y) {
            above[y] = last, above_row[y] = last_row;
            if (const double k = known(x, y); k >= 0.0) last = k, last_row = y;
        }
        last = -1.0, last_row = h;
        for (size_t y = h; y-- > 0;) {
            below[y] = last, below_row[y] = last_row;
            if (const double k = known(x, y); k >= 0.0) last = k, last_row = y;
        }
        for (size_t y = 0; y < h; ++y) {
            const double own = cost[y * w + x];
            double& o = out[y * w + x];
            if (own >= 0.0)
                o = own;
            else if (above[y] >= 0.0 && below[y] >= 0.0)
                o = above[y] + (below[y] - above[y]) * double(y - above_row[y]) /
                                   double(below_row[y] - above_row[y]);
            else
                o = std::max({above[y], below[y], 0.0});
        }
    }
    return out;
}

double TileWorkEstimate::fraction_done() const {
    const std::vector<double> cost = all_tiles();
    double done = 0.0, all = 0.0;
    size_t tiles_done = 0;
    for (int t : tiles_) {
        if (t < 0 || size_t(t) >= cost.size()) continue;
        const bool finished = cells_[size_t(t)].load(std::memory_order_acquire) > 0;
        tiles_done += finished ? 1 : 0;
        if (finished) done += cost[size_t(t)];
        all += cost[size_t(t)];
    }
    if (!(done > 0.0) || !(all > 0.0))
        return tiles_.empty() ? 1.0 : double(tiles_done) / double(tiles_.size());
    return std::clamp(done / all, 0.0, 1.0);
}

double TileWorkEstimate::predicted_rays(int tile) const {
    const std::vector<double> cost = all_tiles();
    return tile >= 0 && size_t(tile) < cost.size() ? cost[size_t(tile)] : 0.0;
}

}  // namespace vr
