// Reading one large classic-encoding file on all cores. A piece is a byte range of the file read
// into a node tree of its own (the scene layer builds a piece's typed scene, a fragment:
// scene/fragments.h). The file is cut into pieces at lines that look like the start of a top-level
// node; every piece but the first is read speculatively, on its own, into a node tree of its own,
// while the main reader reads the file in order. When the main reader arrives at a piece's first
// byte between two top-level statements, and the file declared no PROTO so far, the piece's tree,
// DEF names, statistics and warnings are appended in file order and the main reader jumps to the
// piece's end. A piece whose read failed, declared PROTOs, or held anything that depends on the
// rest of the file (USE of an earlier DEF, EXTERNPROTO, ROUTE) is simply read again by the main
// reader, so the result and every message equal a single-thread read.
#pragma once
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string_view>
#include <thread>
#include <unordered_map>
#include <vector>

#include "parser/diagnostics.h"
#include "parser/node_tree.h"
#include "parser/piece_consumer.h"

namespace vr {

// The bytes per piece below which a file is read by one thread: a piece must carry enough work
// to pay for its thread and the copy into the main tree.
constexpr size_t kDefaultPieceBytes = size_t(16) << 20;

// The piece size in force: VRMLRAY_PIECE_BYTES when set (tests force small pieces with it; 0
// turns speculation off), else kDefaultPieceBytes.
size_t piece_bytes();

// The threads that read pieces besides the calling one, for `threads` in all (--threads; 0: one a
// core). With none, the calling thread reads every piece itself, in order.
unsigned piece_workers(unsigned threads);

// Offsets where pieces start (the first piece, at `begin`, is not listed): the first line start
// at or after `begin` + `head` (0: `piece`), then after each `piece` bytes more, whose first byte
// is a letter, the way exporters begin top-level nodes. Only a guess: the main reader checks every
// one.
std::vector<SourceOffset> piece_starts(std::string_view text, SourceOffset begin, size_t piece,
                                       size_t head = 0);

// What a speculative read of one piece gives.
struct Piece {
    uint32_t index = 0;               // in file order
    SourceOffset begin = 0, end = 0;  // 64-bit: a file may pass 4 GiB
    NodeTree tree;
    Diagnostics diagnostics;
    ReadStats stats;
    std::vector<NodeId> roots;
    std::unordered_map<Name, NodeId> defs;
    std::vector<Name> outer_uses;  // names USEd from before the piece: outer node k is the k-th
    std::vector<Name> outer_tags;  // XML: the element each was USEd as (its DEF's node type)
    bool usable =
        false;  // read to its end with no error and nothing that needs the rest of the file
    // Taken by the PieceConsumer: `tree` and `roots` are empty; `nodes` and `root_count` say how
    // many nodes and top-level nodes it held.
    bool consumed = false;
    uint32_t nodes = 0;
    uint32_t root_count = 0;
    uint32_t lines = 0;  // XML: the piece's line breaks, which the main reader's libxml2 never sees
};

// Reads pieces on worker threads, in file order, a few ahead of the one the main reader needs
// next (their trees wait in memory until appended).
class PieceScheduler {
  public:
    using ReadFn = std::function<void(Piece&)>;
    // Starts `workers` threads (none when there is a single piece or none).
    PieceScheduler(std::vector<Piece> pieces, ReadFn read, unsigned workers);
    ~PieceScheduler() { stop(); }
    PieceScheduler(const PieceScheduler&) = delete;
    PieceScheduler& operator=(const PieceScheduler&) = delete;

    size_t size() const { return pieces_.size(); }
    SourceOffset begin(size_t k) const { return pieces_[k].begin; }
    // Piece k, read; while a worker still reads it, this thread reads later pieces. Pieces are
    // asked for in order, each at most once (get or drop).
    Piece& get(size_t k);
    // Piece k is not needed: not read if no thread has begun it, and its memory freed.
    void drop(size_t k);
    // No piece is begun any more; returns when the running ones have ended.
    void stop();

  private:
    enum class State : uint8_t { Waiting, Reading, Done };
    bool claim(size_t& k);  // the next piece to read, if any within the window (lock held)
    void read(size_t k, std::unique_lock<std::mutex>& lock);
    void work();

    std::vector<Piece> pieces_;
    std::vector<State> state_;
    std::vector<bool> dropped_;  // by the main reader while a worker read it
    ReadFn read_;
    std::mutex mutex_;
    std::condition_variable changed_;
    size_t next_ = 0;   // lowest piece no thread has claimed
    size_t front_ = 0;  // lowest piece the main reader has not taken
    size_t window_ = 4;
    bool stopped_ = false;
    std::vector<std::thread> threads_;
};

// Appends `piece` to `tree`: node ids, field, number, string and node-reference indices shifted,
// node kinds re-indexed, outer node k (piece_consumer.h) replaced by outer[k]. Returns the id the
// piece's node 0 gets.
NodeId append_tree(NodeTree& tree, NodeTree&& piece, std::span<const NodeId> outer = {});
// A piece's node reference (a root, say) as it reads in `tree` after append_tree gave `base`.
inline NodeId appended_id(NodeId id, NodeId base, std::span<const NodeId> outer) {
    return id == kNullNode ? id : is_outer_node(id) ? outer[id - kFirstOuterNode] : id + base;
}
// Adds the counts of a later part of the same file.
void append_stats(ReadStats& stats, const ReadStats& later);

// What the main reader has read so far, which a piece joins (both encodings' readers).
struct PieceJoin {
    NodeTree& tree;
    std::vector<NodeId>& roots;              // top-level nodes
    std::unordered_map<Name, NodeId>& defs;  // the file's DEF names
    std::vector<ConsumedPiece>& consumed;    // pieces a PieceConsumer took
    size_t& consumed_nodes;                  // their nodes, counted against the node limit
    ReadStats& stats;
    Diagnostics& diagnostics;
};
// Joins `piece`, whose outer nodes stand for `outer`, after the roots read so far: a consumed
// piece as its record, another with its nodes appended and its roots and DEF names renumbered (a
// skipped node's DEF, kNullNode, stays so); then its counts and messages. `piece` is left empty.
void join_piece(Piece& piece, std::vector<NodeId> outer, const PieceJoin& to);

}  // namespace vr
