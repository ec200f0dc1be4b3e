// Many processes rendering one image (docs/mpi.md). Every MPI call of vrmlray is in the MPI
// module (src/mpi/vrmlray_mpi.cpp), which mpi_processes.cpp loads only when a launcher started this
// process with peers: a plain run loads no MPI library, and a build without MPI (VRMLRAY_MPI off)
// has no module, so both see a world of one process.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace vr {

// A nonblocking send or receive under way (MpiProcesses::send_async, receive_async), until
// MpiProcesses::done or wait ends it; its storage must live until then.
struct MpiRequest {
    void* handle = nullptr;  // the module's; null: none under way
};

class MpiProcesses {
  public:
    // The processes started together with this one. On the first call MPI is initialised when
    // a launcher (mpirun, srun) started more than one process, and finalised at exit.
    static MpiProcesses& get();
    // A world of this process alone: what a process renders of the frames it was dealt, which no
    // other process shares.
    static const MpiProcesses& alone();

    int rank() const { return rank_; }
    int size() const { return size_; }
    bool parallel() const { return size_ > 1; }
    bool root() const { return rank_ == 0; }
    // The seconds MPI's start-up took in this process (0 in a world of one).
    double init_seconds() const { return init_seconds_; }

    // Collectives: every process calls them at the same points, in the same order.
    // The largest exit code of all processes (0 when all succeeded), so that all exit alike.
    int agree(int code) const;
    uint64_t sum(uint64_t value) const;
    double max(double value) const;
    // At rank 0: every process's `mine` (all of one length) one after the other in rank order;
    // elsewhere: empty.
    std::vector<double> gather(const std::vector<double>& mine) const;
    // `pixels` is a width x height image of `pixel_bytes` a pixel, row by row, in which each
    // process holds the tiles of its share (RenderOptions::tile_stride = size(), tile_offset =
    // rank()). Rank 0 receives every other process's tiles into it; the others send theirs.
    void gather_tiles(uint8_t* pixels, size_t pixel_bytes, int width, int height) const;
    // Point to point: a byte string to process `to`, which takes it with receive(from) at the
    // matching point of its own order (a frame file a process rendered, for rank 0 to write).
    void send(const std::vector<uint8_t>& data, int to) const;
    std::vector<uint8_t> receive(int from) const;
    // Nonblocking: `data` to process `to` under `tag`, which takes it with receive_async(from,
    // tag); the receives of one process's sends with one tag match them in their order.
    MpiRequest send_async(std::span<const uint8_t> data, int to, int tag) const;
    MpiRequest receive_async(std::span<uint8_t> data, int from, int tag) const;
    // Whether `request` is done (then ended); also drives MPI's progress.
    bool done(MpiRequest& request) const;
    void wait(MpiRequest& request) const;
    // Process `root`'s `data` into every process's `data` (resized to it).
    void broadcast(std::vector<uint8_t>& data, int root) const;

  private:
    MpiProcesses();
    struct Alone {};
    explicit MpiProcesses(Alone) {}
    int rank_ = 0, size_ = 1;
    double init_seconds_ = 0.0;
};

// Whether the environment says a launcher started this process with peers (Open MPI's mpirun,
// MPICH's hydra, srun with PMI or PMIx): only then is MPI initialised, so that a plain run costs
// nothing and does not try to reach a launcher that is not there.
bool launched_with_peers();

}  // namespace vr
