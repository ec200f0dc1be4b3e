// A consumer of the pieces a large classic-encoding file is read in (classic_pieces.h): it builds
// what it needs from a piece's node tree on the thread that read the piece, so that the tree of a
// large file is never held whole (src/scene/fragments.h builds typed scene fragments this way).
// The parser knows only this interface: data still flows one way, file -> tree -> scene.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "parser/node_tree.h"

namespace vr {

// A piece read on its own may USE what a DEF before it names: such a node stands in the piece's
// tree as kFirstOuterNode + k, the piece's k-th such name, until the main reader, arriving at the
// piece, finds those DEFs (Piece::outer_uses, ConsumedPiece::outer_nodes). The reader keeps node
// ids below it (its node limit never exceeds it).
constexpr NodeId kFirstOuterNode = 0xC0000000u;
inline bool is_outer_node(NodeId id) { return id >= kFirstOuterNode && id != kNullNode; }

class PieceConsumer {
  public:
    virtual ~PieceConsumer() = default;
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
