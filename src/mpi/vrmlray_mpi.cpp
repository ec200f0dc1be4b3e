// The MPI module: vrmlray's MPI calls behind the plain C interface of mpi_abi.h.
#include <mpi.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "mpi/mpi_abi.h"

namespace {
// Messages are cut to this (MPI counts are int).
constexpr size_t kChunk = size_t(1) << 30;
constexpr int kTag = 16;
}  // namespace

extern "C" {

int vrmlray_mpi_abi_version() { return VRMLRAY_MPI_ABI_VERSION; }

void vrmlray_mpi_init(int* rank, int* size) {
#ifdef OPEN_MPI
    // Open MPI opens every point-to-point layer (PML) before it picks one; opening cm, whose fabric
    // layers (libfabric, PSM) probe the network devices, took most of MPI_Init's time on the
    // 2-core test machine (bench/README.md, "Figures behind the comments"), which then picked ob1
    // anyway. When every process is on this node (local
    // size = world size, the same answer in every process, so all pick alike) ob1 with its
    // shared-memory transport is what a node needs, so it is named here unless the user named a PML
    // (--mca pml, OMPI_MCA_pml: both arrive as this variable, which setenv then leaves alone).
    // docs/mpi.md.
    const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
    const char* world = std::getenv("OMPI_COMM_WORLD_SIZE");
    if (local != nullptr && world != nullptr && std::strcmp(local, world) == 0)
        setenv("OMPI_MCA_pml", "ob1", 0);
#endif
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, rank);
    MPI_Comm_size(MPI_COMM_WORLD, size);
}

void vrmlray_mpi_finalize() {
    int done = 0;
    MPI_Finalized(&done);
    if (!done) MPI_Finalize();
}

int vrmlray_mpi_max_int(int value) {
    MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return value;
}

uint64_t vrmlray_mpi_sum_u64(uint64_t value) {
    MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    return value;
}

double vrmlray_mpi_max_double(double value) {
    MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return value;
}

void vrmlray_mpi_gather_doubles(const double* mine, int n, double* all) {
    MPI_Gather(mine, n, MPI_DOUBLE, all, n, MPI_DOUBLE, 0, MPI_COMM_WORLD);
}

void vrmlray_mpi_send(const void* data, size_t bytes, int to) {
    const char* p = static_cast<const char*>(data);
    for (size_t at = 0; at < bytes; at += kChunk)
        MPI_Send(p + at, int(std::min(kChunk, bytes - at)), MPI_BYTE, to, kTag, MPI_COMM_WORLD);
}

void vrmlray_mpi_recv(void* data, size_t bytes, int from) {
    char* p = static_cast<char*>(data);
    for (size_t at = 0; at < bytes; at += kChunk)
        MPI_Recv(p + at, int(std::min(kChunk, bytes - at)), MPI_BYTE, from, kTag, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
}

void vrmlray_mpi_bcast(void* data, size_t bytes, int root) {
    char* p = static_cast<char*>(data);
    for (size_t at = 0; at < bytes; at += kChunk)
        MPI_Bcast(p + at, int(std::min(kChunk, bytes - at)), MPI_BYTE, root, MPI_COMM_WORLD);
}

// A nonblocking message: one MPI request per chunk.
struct Request {
    std::vector<MPI_Request> chunks;
};

void* vrmlray_mpi_isend(const void* data, size_t bytes, int to, int tag) {
    auto* r = new Request;
    const char* p = static_cast<const char*>(data);
    for (size_t at = 0; at < bytes; at += kChunk)
        MPI_Isend(p + at, int(std::min(kChunk, bytes - at)), MPI_BYTE, to, tag, MPI_COMM_WORLD,
                  &r->chunks.emplace_back());
    return r;
}

void* vrmlray_mpi_irecv(void* data, size_t bytes, int from, int tag) {
    auto* r = new Request;
    char* p = static_cast<char*>(data);
    for (size_t at = 0; at < bytes; at += kChunk)
        MPI_Irecv(p + at, int(std::min(kChunk, bytes - at)), MPI_BYTE, from, tag, MPI_COMM_WORLD,
                  &r->chunks.emplace_back());
    return r;
}

int vrmlray_mpi_test(void* request) {
    auto* r = static_cast<Request*>(request);
    int done = 0;
    MPI_Testall(int(r->chunks.size()), r->chunks.data(), &done, MPI_STATUSES_IGNORE);
    if (done) delete r;
    return done;
}

void vrmlray_mpi_wait(void* request) {
    auto* r = static_cast<Request*>(request);
    MPI_Waitall(int(r->chunks.size()), r->chunks.data(), MPI_STATUSES_IGNORE);
    delete r;
}

}  // extern "C"
