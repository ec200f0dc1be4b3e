// Processes that split the reading of a large file (docs/mpi.md "Split reading"). Under
// `mpirun -np N` every process still reads the file's head and its top-level structure, but of the
// pieces the parallel reader cuts the file into (parser/classic_pieces.h), process r builds only
// pieces r, r + N, r + 2N, ... into scene fragments (src/scene/plain_piece.h), on its --threads,
// and sends each to every other process as soon as it is built, taking in theirs between its own
// pieces; every process then hands the reader all the fragments as if its own threads had built
// them. The scene each process builds is then the one a
// single process builds, so the image stays the same bytes.
//
// What is not shared stays as it was: a piece that is not plain (whose owner's plain reader gave
// up) is read by every process itself, as are files the reader does not cut (small files, X3D XML,
// VRML 1) and pieces the reader cannot use after all (a PROTO before them, a UNIT angle).
#pragma once
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "app/mpi_processes.h"
#include "scene/fragments.h"
#include "scene/plain_piece.h"

namespace vr {

// The bytes to cut a file of `file_bytes` into pieces when `processes` share them: small enough
// that each process gets a dozen or more (so that the head every process reads and the unevenness
// of the deal are small), at most what one process uses.
size_t shared_piece_bytes(size_t file_bytes, int processes);
constexpr size_t kSharedHeadBytes = size_t(64) << 10;
// The bytes of the head before the first piece (`piece`: shared_piece_bytes), which every process
// reads itself: as short as the head of an export is (its lights, viewpoint and DEF'd
// appearances), not a piece's worth. A cut inside the head's statements costs nothing wrong: the
// reader drops that piece and reads its text itself.
size_t shared_head_bytes(size_t piece);

// What one process did of the reading, for --stats (processes[].reading).
struct SharedReading {
    double read_seconds = 0.0;      // building its own pieces
    double exchange_seconds = 0.0;  // sending and taking in, and waiting for the last pieces
    uint64_t pieces = 0;            // pieces the file was cut into
    uint64_t built_here = 0;        // of them built by this process
    uint64_t received = 0;          // built by another and received
    uint64_t bytes_sent = 0;        // this process's pieces, once (each goes to every other)
};

class SharedPieces final : public PieceConsumer, public FragmentStore {
  public:
    // `threads`: this process's --threads (0: one a core).
    SharedPieces(const MpiProcesses& world, int threads) : world_(world), threads_(threads) {}

    // Collective: every process's reader calls it at the same point.
    void plan(std::span<const PieceText> pieces) override;
    std::optional<TextConsumed> consume_text(size_t piece, const PieceText& text) override;
    bool consume(size_t piece, const NodeTree& tree, std::span<const NodeId> roots) override {
        return local_.consume(piece, tree, roots);
    }
    void discard(size_t piece) override;
    Scene* fragment(size_t piece) override;
    void release(size_t piece) override { discard(piece); }

    const SharedReading& figures() const { return figures_; }
    // The exit code the processes agreed on when the reading began (plan): not kExitOk when
    // another process failed before it reached the pieces, in which case the caller returns it
    // without agreeing again.
    int agreed() const { return agreed_; }

  private:
    enum class State : uint8_t { Unplanned, NotPlain, Ready, Taken };
    struct Slot {
        State state = State::Unplanned;
        std::unique_ptr<Scene> fragment;
        TextConsumed counts;
    };
    // Puts a piece built here or received into its slot (null: not plain).
    void keep(size_t piece, std::unique_ptr<Scene> fragment, TextConsumed counts);

    const MpiProcesses& world_;
    int threads_;
    SceneFragments local_;  // pieces this process reads itself after all
    std::mutex mutex_;
    std::vector<Slot> slots_;  // by piece
    SharedReading figures_;
    int agreed_ = 0;
};

}  // namespace vr
