// How much of a render is done, measured in rays of every kind (camera, shadow, sky and area
// light, reflection and refraction), for the progress bar: the rays of the tiles traced so far
// against those plus a prediction of the rays of the tiles still to trace, each predicted from
// the traced tiles of its column in the nearest traced tile rows above and below it
// (docs/rendering.md, "Progress"). Tiles are traced rows-coarse-first (trace_order) so that
// traced rows are spread over the image early and every untraced row has traced neighbours.
#pragma once
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

namespace vr {

// `tiles` (tile ids, row by row in a grid `tiles_x` wide) reordered so that their tile rows come
// in van der Corput order (0, 1/2, 1/4, 3/4, 1/8, ... of the grid's height), each row left to
// right: after any share of the rows, the traced ones are spread evenly over the image.
std::vector<int> trace_order(const std::vector<int>& tiles, int tiles_x, int tiles_y);

class TileWorkEstimate {
  public:
    // `tiles`: the tile ids this render traces, in a grid tiles_x x tiles_y.
    TileWorkEstimate(const std::vector<int>& tiles, int tiles_x, int tiles_y);
    // Tile `tile` (an id of `tiles`) is done and took `rays`; from any thread.
    void record(int tile, uint64_t rays);
    // The rays of the done tiles over those plus the predicted rays of the others; the share of
    // the tiles done while no tile has taken a ray. From one thread at a time.
    double fraction_done() const;
    // The predicted rays of tile `tile` (its own when done): for the tests.
    double predicted_rays(int tile) const;

  private:
    // Every tile's rays (done) or prediction (not done).
    std::vector<double> all_tiles() const;
    int tiles_x_, tiles_y_;
    std::vector<int> tiles_;
    // Per grid cell: -1 not part of the render, else 0 while untraced, rays + 1 once done.
    std::unique_ptr<std::atomic<int64_t>[]> cells_;
};

}  // namespace vr
