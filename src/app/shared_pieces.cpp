#include "app/shared_pieces.h"

#include <algorithm>
#include <chrono>
#include <new>
#include <stdexcept>
#include <thread>

#include "app/commands.h"
#include "app/fragment_wire.h"
#include "app/render_mpi.h"
#include "core/parallel.h"
#include "parser/classic_pieces.h"
#include "scene/plain_piece.h"

namespace vr {
namespace {

double seconds_from(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

size_t shared_piece_bytes(size_t file_bytes, int processes) {
    // 16 pieces a process: the head (one piece, read by all) is then 1/16 of a share, and a deal
    // of whole pieces is even to a sixteenth. Not below 1 MiB: a piece must carry enough work to
    // pay for its fragment and its splice.
    const size_t fine =
        std::max<size_t>(size_t(1) << 20, file_bytes / (16 * size_t(std::max(processes, 1))));
    return std::min(piece_bytes(), fine);  // VRMLRAY_PIECE_BYTES (tests: smaller; 0: none) wins
}

void SharedPieces::plan(std::span<const PieceText> pieces) {
    figures_.pieces = pieces.size();
    // One piece or none: a small file, read whole by every process (the same decision in each, as
    // all read the same file, so no process waits for a collective the others skip).
    if (!world_.parallel() || pieces.size() < 2) return;
    agreed_ = vr::agreed(world_, kExitOk, "reading the scene");
    if (agreed_ != kExitOk) return;  // another process could not read the file

    const auto start = std::chrono::steady_clock::now();
    std::vector<size_t> mine;  // pieces rank, rank + size, ...: the pieces are of one size
    for (size_t k = size_t(world_.rank()); k < pieces.size(); k += size_t(world_.size()))
        mine.push_back(k);
    std::vector<std::optional<PlainPiece>> built(mine.size());
    const int threads =
        threads_ > 0 ? threads_ : int(std::max(1u, std::thread::hardware_concurrency()));
    parallel_ranges(mine.size(), threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) try {
                built[i] = read_plain_piece(pieces[mine[i]]);
            } catch (const std::bad_alloc&) {
                built[i].reset();  // sent as not plain: every process reads it itself
            }
    });
    figures_.read_seconds = seconds_from(start);
    const auto exchange_start = std::chrono::steady_clock::now();
    slots_.resize(pieces.size());
    exchange(built, mine);
    figures_.exchange_seconds = seconds_from(exchange_start);
}

// Each process packs what it built; each in turn broadcasts its message; then every process
// unpacks the others' messages (on its threads) into its slots. Packing and unpacking run in all
// processes at once: only the broadcasts follow one another.
void SharedPieces::exchange(std::vector<std::optional<PlainPiece>>& built,
                            const std::vector<size_t>& mine) {
    const int size = world_.size(), rank = world_.rank();
    std::vector<WirePiece> own(mine.size());
    for (size_t i = 0; i < mine.size(); ++i) {
        own[i].piece = uint32_t(mine[i]);
        if (!built[i]) continue;
        own[i].fragment = std::move(built[i]->fragment);
        own[i].counts = std::move(built[i]->counts);
    }
    built.clear();
    std::vector<std::vector<uint8_t>> messages(static_cast<size_t>(size));
    messages[size_t(rank)] = pack_pieces(own);
    figures_.bytes_sent = messages[size_t(rank)].size();
    for (int root = 0; root < size; ++root) world_.broadcast(messages[size_t(root)], root);
    messages[size_t(rank)] = std::vector<uint8_t>();

    std::vector<std::vector<WirePiece>> got(static_cast<size_t>(size));
    got[size_t(rank)] = std::move(own);
    const int threads =
        threads_ > 0 ? threads_ : int(std::max(1u, std::thread::hardware_concurrency()));
    parallel_ranges(size_t(size), threads, [&](size_t begin, size_t end, int) {
        for (size_t root = begin; root < end; ++root) {
            if (root == size_t(rank)) continue;
            try {
                got[root] = unpack_pieces(messages[root]);
            } catch (const std::exception&) {  // broken, or no memory: read those pieces here
                got[root].clear();
            }
            messages[root] = std::vector<uint8_t>();
        }
    });
    for (size_t root = 0; root < size_t(size); ++root)
        for (WirePiece& p : got[root]) {
            if (p.piece >= slots_.size() || p.piece % size_t(size) != root) continue;
            Slot& slot = slots_[p.piece];
            if (!p.fragment || !fits_wire(*p.fragment)) {
                slot.state = State::NotPlain;
                continue;
            }
            slot.state = State::Ready;
            slot.fragment = std::make_unique<Scene>(std::move(*p.fragment));
            slot.counts = std::move(p.counts);
            ++(root == size_t(rank) ? figures_.built_here : figures_.received);
        }
}

std::optional<TextConsumed> SharedPieces::consume_text(size_t piece, const PieceText& text) {
    {
        std::lock_guard lock(mutex_);
        if (piece < slots_.size()) {
            Slot& slot = slots_[piece];
            // Its owner's plain reader gave up: so would this one, on the same text.
            if (slot.state == State::NotPlain) return std::nullopt;
            if (slot.state == State::Ready) {
                slot.state = State::Taken;
                return std::move(slot.counts);
            }
        }
    }
    return local_.consume_text(piece, text);
}

void SharedPieces::discard(size_t piece) {
    std::unique_ptr<Scene> gone;  // freed outside the lock
    {
        std::lock_guard lock(mutex_);
        if (piece < slots_.size()) gone = std::move(slots_[piece].fragment);
    }
    local_.discard(piece);
}

Scene* SharedPieces::fragment(size_t piece) {
    {
        std::lock_guard lock(mutex_);
        if (piece < slots_.size() && slots_[piece].fragment) return slots_[piece].fragment.get();
    }
    return local_.fragment(piece);
}

}  // namespace vr
