// A minimal fork-join loop over index ranges on std::thread (no pool: the callers are coarse,
// one call per build step). Its ranges are of a loop's indices; not a large file's pieces
// (parser/classic_pieces.h), their typed scenes (scene/fragments.h) or an array's storage blocks
// (scene/chunked_array.h).
#pragma once
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace vr {

// Calls body(begin, end, range) for `ranges` contiguous ranges of [0, n), range 0 on the calling
// thread, each other on a thread of its own. The split depends only on n and ranges, never on
// timing.
template <class Body>
void parallel_ranges(size_t n, int ranges, Body&& body) {
    ranges = int(std::max<size_t>(1, std::min<size_t>(size_t(std::max(ranges, 1)), n)));
    if (ranges == 1) {
        body(size_t(0), n, 0);
        return;
    }
    std::vector<std::thread> workers;
    workers.reserve(size_t(ranges - 1));
    auto bounds = [&](int r) { return n * size_t(r) / size_t(ranges); };
    for (int r = 1; r < ranges; ++r)
        workers.emplace_back([&, r] { body(bounds(r), bounds(r + 1), r); });
    body(bounds(0), bounds(1), 0);
    for (std::thread& t : workers) t.join();
}

// How many ranges (threads) parallel_ranges should use for n items of cheap work: one per ~64k
// items, at most `threads`.
inline int chunks_for(size_t n, int threads) {
    return int(std::max<size_t>(1, std::min<size_t>(size_t(std::max(threads, 1)), n / 65536)));
}

}  // namespace vr
