#include "app/shared_pieces.h"

#include <algorithm>
#include <chrono>
#include <deque>
#include <functional>
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

namespace {

constexpr int kHeaderTag = 45, kPartTag = 46;

// The pieces going out and coming in while this process reads its own. Each built piece goes to
// every other process as its header and its parts (fragment_wire.h), each part sent straight from
// the fragment's arrays; from each other process this one keeps a receive of its next piece's
// header posted, and on the header posts the receives of the parts straight into the arrays of a
// fresh fragment. Nonblocking, so a process that is still reading is not waited for: what has
// arrived is taken in between its own pieces (poll), the rest at the end (finish).
class PieceExchange {
  public:
    using Deliver = std::function<void(size_t piece, std::optional<Scene>, TextConsumed)>;

    PieceExchange(const MpiProcesses& world, size_t pieces, Deliver deliver)
        : world_(world), pieces_(pieces), deliver_(std::move(deliver)) {
        for (int rank = 0; rank < world.size(); ++rank) {
            if (rank == world.rank()) continue;
            Source& s = sources_.emplace_back();
            s.rank = rank;
            s.next = size_t(rank);
            post_header(s);
        }
    }

    // A piece built here (null: not plain), to every other process; the fragment must live
    // until finish().
    void send(size_t piece, const Scene* fragment, const TextConsumed& counts) {
        Sent& sent = sent_.emplace_back();
        sent.piece = std::make_unique<OutgoingPiece>(uint32_t(piece), fragment, counts, names_);
        bytes_sent_ += sent.piece->bytes();
        const WireHeader& header = sent.piece->header();
        const std::span<const uint8_t> header_bytes(reinterpret_cast<const uint8_t*>(&header),
                                                    sizeof header);
        for (const Source& s : sources_) {
            sent.requests.push_back(world_.send_async(header_bytes, s.rank, kHeaderTag));
            for (const std::span<const uint8_t> part : sent.piece->parts())
                sent.requests.push_back(world_.send_async(part, s.rank, kPartTag));
        }
    }
    // Takes in what has arrived, waiting for nothing, and frees what went out.
    void poll() {
        for (Source& s : sources_) advance(s, false);
        for (Sent& sent : sent_) {
            if (!sent.piece) continue;
            if (!std::all_of(sent.requests.begin(), sent.requests.end(),
                             [&](MpiRequest& r) { return world_.done(r); }))
                break;           // the later ones went out after it
            sent.piece.reset();  // its geometry records
        }
    }
    // Takes in every other process's pieces and waits until this one's are sent.
    void finish() {
        for (Source& s : sources_) advance(s, true);
        for (Sent& sent : sent_)
            for (MpiRequest& r : sent.requests) world_.wait(r);
        sent_.clear();
    }
    uint64_t bytes_sent() const { return bytes_sent_; }

  private:
    // One other process, whose pieces rank, rank + N, ... arrive in order.
    struct Source {
        int rank = 0;
        size_t next = 0;  // the piece expected next
        WireHeader header;
        MpiRequest header_request;
        std::unique_ptr<IncomingPiece> incoming;  // its parts under way
        std::vector<MpiRequest> part_requests;
        NameMap names;
    };

    void post_header(Source& s) {
        if (s.next >= pieces_) return;
        s.header_request = world_.receive_async(
            {reinterpret_cast<uint8_t*>(&s.header), sizeof s.header}, s.rank, kHeaderTag);
    }

    // Moves `s` on as far as what arrived allows (`block`: until its last piece is in).
    void advance(Source& s, bool block) {
        for (;;) {
            if (s.incoming) {
                for (MpiRequest& r : s.part_requests) {
                    if (block) world_.wait(r);
                    if (!world_.done(r)) return;
                }
                take(s);
                continue;
            }
            if (s.header_request.handle == nullptr) return;  // every piece of it is in
            if (block) world_.wait(s.header_request);
            if (!world_.done(s.header_request)) return;
            if (s.header.piece != s.next)
                throw std::runtime_error("a process sent a piece out of its order");
            s.incoming = std::make_unique<IncomingPiece>(s.header);
            for (const std::span<uint8_t> part : s.incoming->parts())
                s.part_requests.push_back(world_.receive_async(part, s.rank, kPartTag));
        }
    }

    void take(Source& s) {
        TextConsumed counts;
        std::optional<Scene> fragment;
        try {
            fragment = std::move(*s.incoming).finish(s.names, counts);
        } catch (const std::runtime_error&) {  // parts that do not fit: read the piece here
            fragment.reset();
        }
        deliver_(s.next, std::move(fragment), std::move(counts));
        s.incoming.reset();
        s.part_requests.clear();
        s.next += size_t(world_.size());
        post_header(s);
    }

    const MpiProcesses& world_;
    size_t pieces_;
    Deliver deliver_;
    NameTexts names_;
    std::deque<Source> sources_;  // a deque: a Source receives into itself, so it must not move
    // A piece of this process's on its way to the others.
    struct Sent {
        std::unique_ptr<OutgoingPiece> piece;
        std::vector<MpiRequest> requests;
    };
    std::vector<Sent> sent_;
    uint64_t bytes_sent_ = 0;
};

}  // namespace

size_t shared_head_bytes(size_t piece) {
    // A 174 MB file of 1M spheres on 2 processes: a head of a piece (5.4 MB) was 0.025 s of the
    // 0.24 s each process read (bench/README.md, "Issue 45: split reading, the exchange").
    return std::min(piece, kSharedHeadBytes);
}

void SharedPieces::plan(std::span<const PieceText> pieces) {
    figures_.pieces = pieces.size();
    // One piece or none: a small file, read whole by every process (the same decision in each, as
    // all read the same file, so no process waits for a collective the others skip).
    if (!world_.parallel() || pieces.size() < 2) return;
    agreed_ = vr::agreed(world_, kExitOk, "reading the scene");
    if (agreed_ != kExitOk) return;  // another process could not read the file

    const auto start = std::chrono::steady_clock::now();
    slots_.resize(pieces.size());
    std::vector<size_t> mine;  // pieces rank, rank + size, ...: the pieces are of one size
    for (size_t k = size_t(world_.rank()); k < pieces.size(); k += size_t(world_.size()))
        mine.push_back(k);
    const int threads =
        threads_ > 0 ? threads_ : int(std::max(1u, std::thread::hardware_concurrency()));
    PieceExchange exchange(
        world_, pieces.size(),
        [this](size_t piece, std::optional<Scene> fragment, TextConsumed counts) {
            if (fragment) ++figures_.received;
            keep(piece, fragment ? std::make_unique<Scene>(std::move(*fragment)) : nullptr,
                 std::move(counts));
        });
    // A piece a thread at a time; between these batches the built pieces go out and what arrived
    // is taken in, so the exchange runs beside the reading instead of after it.
    for (size_t first = 0; first < mine.size(); first += size_t(threads)) {
        std::vector<std::optional<PlainPiece>> built(
            std::min(mine.size() - first, size_t(threads)));
        const auto reading = std::chrono::steady_clock::now();
        parallel_ranges(built.size(), threads, [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i) try {
                    built[i] = read_plain_piece(pieces[mine[first + i]]);
                } catch (const std::bad_alloc&) {
                    built[i].reset();  // sent as not plain: every process reads it itself
                }
        });
        figures_.read_seconds += seconds_from(reading);
        for (size_t i = 0; i < built.size(); ++i) {
            const size_t piece = mine[first + i];
            const bool plain = built[i] && fits_wire(built[i]->fragment);
            if (plain) ++figures_.built_here;
            keep(piece, plain ? std::make_unique<Scene>(std::move(built[i]->fragment)) : nullptr,
                 plain ? std::move(built[i]->counts) : TextConsumed());
            exchange.send(piece, slots_[piece].fragment.get(), slots_[piece].counts);
        }
        exchange.poll();
    }
    exchange.finish();
    figures_.bytes_sent = exchange.bytes_sent();
    figures_.exchange_seconds = seconds_from(start) - figures_.read_seconds;
}

// On the reading thread, before the reader's workers start: no lock.
void SharedPieces::keep(size_t piece, std::unique_ptr<Scene> fragment, TextConsumed counts) {
    if (piece >= slots_.size()) return;
    Slot& slot = slots_[piece];
    slot.state = fragment ? State::Ready : State::NotPlain;
    slot.fragment = std::move(fragment);
    slot.counts = std::move(counts);
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
