// The interface of vrmlray_mpi.so, the MPI module (src/mpi/vrmlray_mpi.cpp), which
// src/app/mpi_processes.cpp loads only when a launcher started vrmlray with peers: linked, Open
// MPI's libraries would slow every start (bench/README.md, "Figures behind the comments"). Plain C
// types only; the version changes with any signature.
#pragma once
#include <cstddef>
#include <cstdint>

#define VRMLRAY_MPI_ABI_VERSION 3

extern "C" {
using VrMpiAbiVersionFn = int (*)();
// MPI_Init_thread (one thread at a time uses MPI: the main one, or the reader's, which the main
// one waits for), then this process's rank and the count.
using VrMpiInitFn = void (*)(int* rank, int* size);
using VrMpiFinalizeFn = void (*)();
// Allreduce over every process: the largest int, the sum of uint64, the largest double.
using VrMpiMaxIntFn = int (*)(int);
using VrMpiSumU64Fn = uint64_t (*)(uint64_t);
using VrMpiMaxDoubleFn = double (*)(double);
// MPI_Gather of n doubles from each process into `all` (size x n) at rank 0.
using VrMpiGatherDoublesFn = void (*)(const double* mine, int n, double* all);
// Point to point, any byte count (cut into messages MPI's int counts can hold).
using VrMpiSendFn = void (*)(const void* data, size_t bytes, int to);
using VrMpiRecvFn = void (*)(void* data, size_t bytes, int from);
// MPI_Bcast of `bytes` bytes from process `root` into every other's `data` (any byte count).
using VrMpiBcastFn = void (*)(void* data, size_t bytes, int root);
// Nonblocking point to point (MPI_Isend, MPI_Irecv) of any byte count under `tag`: a request that
// test (true once done) or wait ends and frees. A receive matches the sends of `from` with its tag
// in the order they were made.
using VrMpiIsendFn = void* (*)(const void* data, size_t bytes, int to, int tag);
using VrMpiIrecvFn = void* (*)(void* data, size_t bytes, int from, int tag);
using VrMpiTestFn = int (*)(void* request);
using VrMpiWaitFn = void (*)(void* request);
}
