#include "app/mpi_world.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "render/options.h"
#include "render/render.h"

#ifdef VRMLRAY_MPI
#include <mpi.h>
#endif

namespace vr {
namespace {

long env_count(const char* name) {
    const char* v = std::getenv(name);
    return v != nullptr ? std::strtol(v, nullptr, 10) : 0;
}

}  // namespace

bool launched_with_peers() {
    return env_count("OMPI_COMM_WORLD_SIZE") > 1 || env_count("PMI_SIZE") > 1 ||
           env_count("PMIX_SIZE") > 1 ||
           (env_count("SLURM_NTASKS") > 1 &&
            (std::getenv("PMIX_RANK") != nullptr || std::getenv("PMI_RANK") != nullptr));
}

#ifdef VRMLRAY_MPI

namespace {

// One process's tiles of a width x height image, each cut to the image, in increasing order.
std::vector<TileRect> share_of(int rank, int ranks, int width, int height) {
    RenderOptions o;
    o.width = width;
    o.height = height;
    o.tile_stride = ranks;
    o.tile_offset = rank;
    std::vector<TileRect> rects;
    for (int t : tiles_of(o)) rects.push_back(tile_rect(t, width, height));
    return rects;
}

// A share's pixels packed for one message: tile after tile, each row by row.
size_t packed_bytes(const std::vector<TileRect>& share, size_t pixel_bytes) {
    size_t n = 0;
    for (const TileRect& r : share) n += size_t(r.x1 - r.x0) * size_t(r.y1 - r.y0) * pixel_bytes;
    return n;
}
// copy(row in the image, the same row in the packed buffer, bytes), for each row in packing order.
template <class Copy>
void for_each_row(const std::vector<TileRect>& share, uint8_t* pixels, size_t pixel_bytes,
                  int width, uint8_t* packed, Copy copy) {
    for (const TileRect& r : share) {
        const size_t row = size_t(r.x1 - r.x0) * pixel_bytes;
        for (int y = r.y0; y < r.y1; ++y, packed += row)
            copy(pixels + (size_t(y) * size_t(width) + size_t(r.x0)) * pixel_bytes, packed, row);
    }
}

// Messages of one rank to rank 0 are cut to this (MPI counts are int).
constexpr size_t kChunk = size_t(1) << 30;
constexpr int kTileTag = 16;

void finalize() {
    int done = 0;
    MPI_Finalized(&done);
    if (!done) MPI_Finalize();
}
}  // namespace

World::World() {
    if (!launched_with_peers()) return;
    const auto start = std::chrono::steady_clock::now();
    int provided = 0;
    // Only the main thread calls MPI; the tracing threads never do.
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    std::atexit(finalize);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    init_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int World::agree(int code) const {
    if (!parallel()) return code;
    MPI_Allreduce(MPI_IN_PLACE, &code, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return code;
}

uint64_t World::sum(uint64_t value) const {
    if (!parallel()) return value;
    MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    return value;
}

double World::max(double value) const {
    if (!parallel()) return value;
    MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return value;
}

std::vector<double> World::gather(const std::vector<double>& mine) const {
    if (!parallel()) return mine;
    std::vector<double> all(root() ? mine.size() * size_t(size_) : 0);
    MPI_Gather(mine.data(), int(mine.size()), MPI_DOUBLE, all.data(), int(mine.size()), MPI_DOUBLE,
               0, MPI_COMM_WORLD);
    return all;
}

void World::gather_tiles(uint8_t* pixels, size_t pixel_bytes, int width, int height) const {
    if (!parallel()) return;
    auto transfer = [&](uint8_t* data, size_t bytes, int peer) {
        for (size_t at = 0; at < bytes; at += kChunk) {
            const int n = int(std::min(kChunk, bytes - at));
            if (root())
                MPI_Recv(data + at, n, MPI_BYTE, peer, kTileTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            else
                MPI_Send(data + at, n, MPI_BYTE, 0, kTileTag, MPI_COMM_WORLD);
        }
    };
    std::vector<uint8_t> packed;
    if (!root()) {
        const std::vector<TileRect> share = share_of(rank_, size_, width, height);
        packed.resize(packed_bytes(share, pixel_bytes));
        for_each_row(share, pixels, pixel_bytes, width, packed.data(),
                     [](uint8_t* image, uint8_t* p, size_t n) { std::memcpy(p, image, n); });
        transfer(packed.data(), packed.size(), 0);
        return;
    }
    for (int peer = 1; peer < size_; ++peer) {
        const std::vector<TileRect> share = share_of(peer, size_, width, height);
        packed.resize(packed_bytes(share, pixel_bytes));
        transfer(packed.data(), packed.size(), peer);
        for_each_row(share, pixels, pixel_bytes, width, packed.data(),
                     [](uint8_t* image, uint8_t* p, size_t n) { std::memcpy(image, p, n); });
    }
}

#else  // a world of one: every collective is the identity

World::World() {
    // mpirun -np N of a binary built without MPI: N processes that each render the whole image.
    if (launched_with_peers() && env_count("OMPI_COMM_WORLD_RANK") + env_count("PMI_RANK") == 0)
        std::fprintf(stderr,
                     "vrmlray: warning: started by an MPI launcher, but built without MPI: every "
                     "process renders the whole image alone\n");
}
int World::agree(int code) const { return code; }
uint64_t World::sum(uint64_t value) const { return value; }
double World::max(double value) const { return value; }
std::vector<double> World::gather(const std::vector<double>& mine) const { return mine; }
void World::gather_tiles(uint8_t*, size_t, int, int) const {}

#endif

World& World::get() {
    static World world;
    return world;
}

}  // namespace vr
