#include "app/mpi_processes.h"

#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/huge_pages.h"
#include "image/module_path.h"
#include "mpi/mpi_abi.h"
#include "render/render.h"

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

// The module's functions (mpi_abi.h), bound once.
struct Module {
    VrMpiInitFn init = nullptr;
    VrMpiFinalizeFn finalize = nullptr;
    VrMpiMaxIntFn max_int = nullptr;
    VrMpiSumU64Fn sum_u64 = nullptr;
    VrMpiMaxDoubleFn max_double = nullptr;
    VrMpiGatherDoublesFn gather_doubles = nullptr;
    VrMpiSendFn send = nullptr;
    VrMpiRecvFn recv = nullptr;
    VrMpiBcastFn bcast = nullptr;
    VrMpiIsendFn isend = nullptr;
    VrMpiIrecvFn irecv = nullptr;
    VrMpiTestFn test = nullptr;
    VrMpiWaitFn wait = nullptr;
};
Module g_mpi;

template <typename Fn>
bool bind(void* handle, const char* name, Fn& fn) {
    fn = reinterpret_cast<Fn>(dlsym(handle, name));
    return fn != nullptr;
}

// Defined by the build when it makes the module (VRMLRAY_MPI on).
#ifndef VRMLRAY_MPI_MODULE_PATH
#define VRMLRAY_MPI_MODULE_PATH ""
#endif
constexpr bool kBuiltWithMpi = sizeof(VRMLRAY_MPI_MODULE_PATH) > 1;

// Loads vrmlray_mpi.so; "" when it is bound, else why not. RTLD_GLOBAL: Open MPI's own plugins,
// which it dlopens in turn, resolve their symbols against libmpi.
std::string load_module() {
    std::string why = "built without MPI (VRMLRAY_MPI=OFF)";
    if (!kBuiltWithMpi) return why;
    for (const std::string& path : module_candidates("vrmlray_mpi.so", VRMLRAY_MPI_MODULE_PATH)) {
        void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
        if (handle == nullptr) {
            const char* e = dlerror();
            why = e != nullptr ? e : path + ": cannot be loaded";  // dlerror names the file
            continue;
        }
        VrMpiAbiVersionFn version = nullptr;
        Module m;
        if (bind(handle, "vrmlray_mpi_abi_version", version) &&
            version() == VRMLRAY_MPI_ABI_VERSION && bind(handle, "vrmlray_mpi_init", m.init) &&
            bind(handle, "vrmlray_mpi_finalize", m.finalize) &&
            bind(handle, "vrmlray_mpi_max_int", m.max_int) &&
            bind(handle, "vrmlray_mpi_sum_u64", m.sum_u64) &&
            bind(handle, "vrmlray_mpi_max_double", m.max_double) &&
            bind(handle, "vrmlray_mpi_gather_doubles", m.gather_doubles) &&
            bind(handle, "vrmlray_mpi_send", m.send) && bind(handle, "vrmlray_mpi_recv", m.recv) &&
            bind(handle, "vrmlray_mpi_bcast", m.bcast) &&
            bind(handle, "vrmlray_mpi_isend", m.isend) &&
            bind(handle, "vrmlray_mpi_irecv", m.irecv) &&
            bind(handle, "vrmlray_mpi_test", m.test) && bind(handle, "vrmlray_mpi_wait", m.wait)) {
            g_mpi = m;
            return "";
        }
        why = path + ": not vrmlray's MPI module of interface version " +
              std::to_string(VRMLRAY_MPI_ABI_VERSION);
    }
    return why;
}

void finalize() { g_mpi.finalize(); }

}  // namespace

MpiProcesses::MpiProcesses() {
    if (!launched_with_peers()) return;
    const auto start = std::chrono::steady_clock::now();
    const std::string why = load_module();
    if (!why.empty()) {
        // N processes that each render the whole image: what a build without MPI does.
        if (env_count("OMPI_COMM_WORLD_RANK") + env_count("PMI_RANK") == 0)
            std::fprintf(stderr,
                         "vrmlray: warning: started by an MPI launcher, but MPI is not available "
                         "(%s): every process renders the whole image alone\n",
                         why.c_str());
        return;
    }
    g_mpi.init(&rank_, &size_);
    std::atexit(finalize);
    init_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int MpiProcesses::agree(int code) const { return parallel() ? g_mpi.max_int(code) : code; }

uint64_t MpiProcesses::sum(uint64_t value) const {
    return parallel() ? g_mpi.sum_u64(value) : value;
}

double MpiProcesses::max(double value) const {
    return parallel() ? g_mpi.max_double(value) : value;
}

std::vector<double> MpiProcesses::gather(const std::vector<double>& mine) const {
    if (!parallel()) return mine;
    std::vector<double> all(root() ? mine.size() * size_t(size_) : 0);
    g_mpi.gather_doubles(mine.data(), int(mine.size()), all.data());
    return all;
}

void MpiProcesses::gather_tiles(uint8_t* pixels, size_t pixel_bytes, int width, int height) const {
    if (!parallel()) return;
    std::vector<uint8_t> packed;
    if (!root()) {
        const std::vector<TileRect> share = share_of(rank_, size_, width, height);
        packed.resize(packed_bytes(share, pixel_bytes));
        for_each_row(share, pixels, pixel_bytes, width, packed.data(),
                     [](uint8_t* image, uint8_t* p, size_t n) { std::memcpy(p, image, n); });
        g_mpi.send(packed.data(), packed.size(), 0);
        return;
    }
    for (int peer = 1; peer < size_; ++peer) {
        const std::vector<TileRect> share = share_of(peer, size_, width, height);
        packed.resize(packed_bytes(share, pixel_bytes));
        g_mpi.recv(packed.data(), packed.size(), peer);
        for_each_row(share, pixels, pixel_bytes, width, packed.data(),
                     [](uint8_t* image, uint8_t* p, size_t n) { std::memcpy(image, p, n); });
    }
}

void MpiProcesses::send(const std::vector<uint8_t>& data, int to) const {
    if (!parallel()) return;
    const uint64_t bytes = data.size();
    g_mpi.send(&bytes, sizeof bytes, to);
    g_mpi.send(data.data(), data.size(), to);
}

std::vector<uint8_t> MpiProcesses::receive(int from) const {
    if (!parallel()) return {};
    uint64_t bytes = 0;
    g_mpi.recv(&bytes, sizeof bytes, from);
    std::vector<uint8_t> data(bytes);
    g_mpi.recv(data.data(), data.size(), from);
    return data;
}

void MpiProcesses::broadcast(std::vector<uint8_t>& data, int root) const {
    if (!parallel()) return;
    uint64_t bytes = data.size();
    g_mpi.bcast(&bytes, sizeof bytes, root);
    if (rank_ != root) resize_huge(data, bytes);  // fresh memory, touched first by the copy
    g_mpi.bcast(data.data(), data.size(), root);
}

MpiRequest MpiProcesses::send_async(std::span<const uint8_t> data, int to, int tag) const {
    if (!parallel()) return {};
    return {g_mpi.isend(data.data(), data.size(), to, tag)};
}

MpiRequest MpiProcesses::receive_async(std::span<uint8_t> data, int from, int tag) const {
    if (!parallel()) return {};
    return {g_mpi.irecv(data.data(), data.size(), from, tag)};
}

bool MpiProcesses::done(MpiRequest& request) const {
    if (request.handle == nullptr) return true;
    if (g_mpi.test(request.handle) == 0) return false;
    request.handle = nullptr;
    return true;
}

void MpiProcesses::wait(MpiRequest& request) const {
    if (request.handle == nullptr) return;
    g_mpi.wait(request.handle);
    request.handle = nullptr;
}

MpiProcesses& MpiProcesses::get() {
    static MpiProcesses world;
    return world;
}

const MpiProcesses& MpiProcesses::alone() {
    static const MpiProcesses world{Alone{}};
    return world;
}

}  // namespace vr
