// A consumer of the pieces (byte ranges read on their own) a large file is read in
// (classic_pieces.h, x3d_xml_pieces.cpp): it builds what it needs from a piece's node tree on the
// thread that read the piece, so that the tree of a large file is never held whole
// (src/scene/fragments.h builds typed scene fragments this way). The parser knows only this
// interface: data still flows one way, file -> tree -> scene.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "parser/node_tree.h"
#include "parser/registry.h"

namespace vr {

// A piece read on its own may USE what a DEF before it names: such a node stands in the piece's
// tree as kFirstOuterNode + k, the piece's k-th such name, until the main reader, arriving at the
// piece, finds those DEFs (Piece::outer_uses, ConsumedPiece::outer_nodes). The reader keeps node
// ids below it (its node limit never exceeds it).
constexpr NodeId kFirstOuterNode = 0xC0000000u;
inline bool is_outer_node(NodeId id) { return id >= kFirstOuterNode && id != kNullNode; }

// A piece's text, for a consumer that reads it itself (PieceConsumer::consume_text).
struct PieceText {
    std::string_view source;  // the whole file
    uint32_t file = 0;
    SourceOffset begin = 0, end = 0;  // the piece's bytes in `source`
    Spec spec = Spec::Vrml97;
    size_t max_nodes = 0;  // the reader's limits for the piece: past them it gives up
    size_t max_depth = 0;
    size_t max_values = 0;  // nodes in one MFNode field
};
// What a consumer that read a piece's text itself took from it: what the reader's tree would have
// counted and the names the piece USEs from before it (outer node k is the k-th, as in Piece).
struct TextConsumed {
    uint32_t roots = 0;
    uint32_t nodes = 0;
    uint32_t uses = 0;  // USE statements (ReadStats::use_count)
    std::vector<Name> outer_uses;
};

class PieceConsumer {
  public:
    virtual ~PieceConsumer() = default;
    // On a reading thread, before the piece is read into a tree: a consumer may read the text
    // itself (src/scene/plain_piece.h builds the scene fragment of a plain piece with no node
    // tree). It must take exactly what consume() would take from the piece's tree, and give up
    // (nullopt) on anything that tree would warn about; the reader then reads the piece as
    // before.
    virtual std::optional<TextConsumed> consume_text(size_t /*piece*/, const PieceText& /*text*/) {
        return std::nullopt;
    }
    // On the reading thread, once, before any piece of the main file is read: every piece it is
    // cut into, in file order (none when the file is read whole). A consumer may build pieces
    // ahead of the reader here, or have other processes build them (src/app/shared_pieces.h);
    // consume_text is still asked for each piece the reader reaches.
    virtual void plan(std::span<const PieceText> /*pieces*/) {}
    // On a reading thread, for the main file's piece `piece` (an index in file order): its tree,
    // read to its end without an error, with no DEF, ROUTE, PROTO, IMPORT or EXPORT in it, and its
    // top-level nodes. Node references may be outer nodes (is_outer_node). True when the consumer
    // took what it needs: the tree is then freed, and the piece stands in
    // LoadedScene::consumed_pieces if the main reader uses it. False: the piece's tree joins the
    // node tree as it would without a consumer.
    virtual bool consume(size_t piece, const NodeTree& tree, std::span<const NodeId> roots) = 0;
    // On the main thread: a consumed piece that the main reader read itself after all (it found
    // the cut inside a statement, say); what was built from it is not used.
    virtual void discard(size_t piece) = 0;
};

// A consumed piece's place among the main file's top-level nodes: its own top-level nodes stand
// before tree.roots[before_root] (after the last when before_root == roots.size()).
struct ConsumedPiece {
    uint32_t piece = 0;
    uint32_t before_root = 0;
    uint32_t roots = 0;  // the piece's top-level nodes, as read
    uint32_t nodes = 0;  // the piece's nodes (for the node limit)
    // The tree's nodes the piece's outer nodes stand for (kNullNode: a skipped node's DEF).
    std::vector<NodeId> outer_nodes;
};

}  // namespace vr
