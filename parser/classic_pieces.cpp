#include "parser/classic_pieces.h"

#include <algorithm>
#include <cstdlib>
#include <string>

namespace vr {

size_t piece_bytes() {
    if (const char* env = std::getenv("VRMLRAY_PIECE_BYTES")) {
        char* end = nullptr;
        const unsigned long long v = std::strtoull(env, &end, 10);
        if (end != env && *end == '\0') return static_cast<size_t>(v);
    }
    return kDefaultPieceBytes;
}

unsigned piece_workers(unsigned threads) {
    const unsigned all = threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
    return all - 1;
}

std::vector<SourceOffset> piece_starts(std::string_view text, SourceOffset begin, size_t piece,
                                       size_t head) {
    std::vector<SourceOffset> starts;
    if (piece == 0) return starts;
    for (size_t at = size_t(begin) + (head > 0 ? head : piece); at < text.size();) {
        size_t line = text.find('\n', at - 1);  // a line start at or after `at`
        if (line == std::string_view::npos || line + 1 >= text.size()) break;
        const unsigned char c = static_cast<unsigned char>(text[line + 1]);
        if ((c | 0x20) >= 'a' && (c | 0x20) <= 'z') {
            starts.push_back(line + 1);
            at = line + 1 + piece;
        } else {
            at = line + 2;
        }
    }
    return starts;
}

PieceScheduler::PieceScheduler(std::vector<Piece> pieces, ReadFn read, unsigned workers)
    : pieces_(std::move(pieces)),
      state_(pieces_.size(), State::Waiting),
      dropped_(pieces_.size(), false),
      read_(std::move(read)) {
    window_ = 2 * (size_t(workers) + 1);
    if (pieces_.empty()) return;
    for (unsigned i = 0; i < workers; ++i) threads_.emplace_back([this] { work(); });
}

bool PieceScheduler::claim(size_t& k) {
    while (next_ < pieces_.size() && state_[next_] != State::Waiting) ++next_;
    if (stopped_ || next_ >= pieces_.size() || next_ >= front_ + window_) return false;
    k = next_++;
    state_[k] = State::Reading;
    return true;
}

void PieceScheduler::read(size_t k, std::unique_lock<std::mutex>& lock) {
    lock.unlock();
    try {
        read_(pieces_[k]);
    } catch (...) {  // out of memory, say: the main reader reads the piece itself
        pieces_[k].usable = false;
    }
    lock.lock();
    state_[k] = State::Done;
    if (dropped_[k]) pieces_[k] = Piece{};
    changed_.notify_all();
}

void PieceScheduler::work() {
    std::unique_lock lock(mutex_);
    for (;;) {
        size_t k = 0;
        if (claim(k)) {
            read(k, lock);
        } else if (stopped_ || next_ >= pieces_.size()) {
            return;
        } else {
            changed_.wait(lock);  // the window moves when the main reader takes a piece
        }
    }
}

Piece& PieceScheduler::get(size_t k) {
    std::unique_lock lock(mutex_);
    front_ = k;
    changed_.notify_all();
    if (state_[k] == State::Waiting) {
        state_[k] = State::Reading;
        read(k, lock);
    }
    while (state_[k] != State::Done) {
        size_t j = 0;
        if (claim(j))
            read(j, lock);
        else
            changed_.wait(lock);
    }
    front_ = k + 1;
    changed_.notify_all();
    return pieces_[k];
}

void PieceScheduler::drop(size_t k) {
    std::unique_lock lock(mutex_);
    front_ = k + 1;
    changed_.notify_all();
    if (state_[k] == State::Reading) {
        dropped_[k] = true;  // its reader frees it; this thread goes on
        return;
    }
    state_[k] = State::Done;
    pieces_[k] = Piece{};
}

void PieceScheduler::stop() {
    {
        std::lock_guard lock(mutex_);
        stopped_ = true;
        changed_.notify_all();
    }
    for (std::thread& t : threads_) t.join();
    threads_.clear();
}

NodeId append_tree(NodeTree& tree, NodeTree&& piece, std::span<const NodeId> outer) {
    const auto node_base = static_cast<NodeId>(tree.nodes.size());
    const auto field_base = static_cast<uint32_t>(tree.fields.size());
    const auto number_base = static_cast<uint32_t>(tree.numbers.size());
    const auto string_base = static_cast<uint32_t>(tree.strings.size());
    const auto ref_base = static_cast<uint32_t>(tree.node_refs.size());

    std::vector<uint32_t> kind(piece.kinds.size());
    for (size_t k = 0; k < kind.size(); ++k)
        kind[k] = k == 0 ? 0 : tree.kind_of(piece.kinds[k].decl, piece.kinds[k].type);
    tree.nodes.reserve(tree.nodes.size() + piece.nodes.size());
    for (NodeId id = 0; id < piece.nodes.size(); ++id) {
        Node n = piece.nodes[id];
        n.kind = kind[n.kind];
        n.first_field += field_base;
        tree.add_node(n, piece.field_count(id));
    }
    auto rebased = [&](FieldEntry e) {
        e.begin += e.type.kind == ValueKind::Node     ? ref_base
                   : e.type.kind == ValueKind::String ? string_base
                                                      : number_base;
        return e;
    };
    tree.fields.reserve(tree.fields.size() + piece.fields.size());
    for (const FieldEntry& e : piece.fields) tree.fields.push_back(rebased(e));
    // A Script's own fields and events (src/script/ runs them) hold values in the same pools.
    for (auto& [id, script] : piece.scripts) {
        for (ScriptField& f : script.fields) f.value = rebased(f.value);
        tree.scripts[id + node_base] = std::move(script);
    }
    tree.numbers.insert(tree.numbers.end(), piece.numbers.begin(), piece.numbers.end());
    for (std::string& s : piece.strings) tree.strings.push_back(std::move(s));
    tree.node_refs.reserve(tree.node_refs.size() + piece.node_refs.size());
    for (NodeId r : piece.node_refs) tree.node_refs.push_back(appended_id(r, node_base, outer));
    piece = NodeTree{};  // its memory goes before the next piece is appended
    return node_base;
}

void append_stats(ReadStats& stats, const ReadStats& later) {
    stats.def_count += later.def_count;
    stats.use_count += later.use_count;
    stats.proto_declarations += later.proto_declarations;
    stats.externproto_declarations += later.externproto_declarations;
    stats.proto_instances += later.proto_instances;
    stats.inline_files += later.inline_files;
    stats.routes += later.routes;
    stats.pieces += later.pieces;
    for (const auto& [type, count] : later.skipped_nodes) stats.skipped_nodes[type] += count;
    stats.foreign_elements += later.foreign_elements;
    const ExporterView& v = later.exporter_view;
    if (v.window_width > 0) {
        stats.exporter_view.window_width = v.window_width;
        stats.exporter_view.window_height = v.window_height;
    }
    if (v.depth_cue) {
        stats.exporter_view.depth_cue = true;
        stats.exporter_view.depth_cue_near = v.depth_cue_near;
        stats.exporter_view.depth_cue_far = v.depth_cue_far;
        stats.exporter_view.depth_cue_has_color = v.depth_cue_has_color;
        stats.exporter_view.depth_cue_color = v.depth_cue_color;
    }
}

void join_piece(Piece& piece, std::vector<NodeId> outer, const PieceJoin& to) {
    if (piece.consumed) {
        to.consumed.push_back({piece.index, static_cast<uint32_t>(to.roots.size()),
                               piece.root_count, piece.nodes, std::move(outer)});
        to.consumed_nodes += piece.nodes;
    } else {
        const NodeId base = append_tree(to.tree, std::move(piece.tree), outer);
        for (NodeId id : piece.roots) to.roots.push_back(appended_id(id, base, outer));
        for (const auto& [name, id] : piece.defs) to.defs[name] = id == kNullNode ? id : id + base;
    }
    append_stats(to.stats, piece.stats);
    ++to.stats.pieces;
    to.diagnostics.append(piece.diagnostics);
    piece = Piece{};
}

}  // namespace vr
