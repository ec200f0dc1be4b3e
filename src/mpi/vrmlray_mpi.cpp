// The MPI module: vrmlray's MPI calls behind the plain C interface of mpi_abi.h.
#include <mpi.h>

#include <algorithm>

#include "mpi/mpi_abi.h"

namespace {
// Messages are cut to this (MPI counts are int).
constexpr size_t kChunk = size_t(1) << 30;
constexpr int kTag = 16;
}  // namespace

extern "C" {

int vrmlray_mpi_abi_version() { return VRMLRAY_MPI_ABI_VERSION; }

void vrmlray_mpi_init(int* rank, int* size) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
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

}  // extern "C"
