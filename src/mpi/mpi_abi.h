// The interface of vrmlray_mpi.so, the MPI module (src/mpi/vrmlray_mpi.cpp), which
// src/app/mpi_processes.cpp loads only when a launcher started vrmlray with peers: linked, Open
// MPI's libraries would slow every start (bench/README.md, "Figures behind the comments"). Plain C
// types only; the version changes with any signature.
#pragma once
#include <cstddef>
#include <cstdint>

#define VRMLRAY_MPI_ABI_VERSION 1

extern "C" {
using VrMpiAbiVersionFn = int (*)();
// MPI_Init_thread (only the calling thread uses MPI), then this process's rank and the count.
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
}
