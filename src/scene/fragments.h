// Typed scene fragments built while a large file is read. A fragment is the typed scene of one
// piece (the parser's name for a byte range of the file read on its own, parser/piece_consumer.h);
// its arrays join the scene's as blocks of a chunked array (chunked_array.h), not copied. The
// reader's worker threads hand each piece of the main file (parser/piece_consumer.h) to
// SceneFragments, which builds the piece's top-level nodes into a Scene of their own and lets the
// reader free the piece's node tree. The scene build (build_scene) then splices the fragments in at
// their places among the top-level nodes, so that the scene equals the one built from the whole
// tree: the same groups, shapes, child lists and merged materials, appearances and spheres, in the
// same order.
//
// A piece is built only when that equality is plain: its nodes are grouping nodes, Shapes,
// Appearances, Materials and the four primitive geometries, nothing in it has metadata, a USE of
// a DEF before the piece stands only as a Shape's appearance (the splice looks it up), and its
// build reports nothing (a warning stays with the node tree, so that messages keep their order).
// Everything else is left to the tree.
#pragma once
#include <atomic>
#include <memory>
#include <mutex>
#include <unordered_map>

#include "parser/load.h"
#include "scene/build.h"
#include "scene/scene.h"

namespace vr {

// Every geometry of `s` is a Sphere, Box, Cylinder or Cone: what a plain piece makes, and all that
// a fragment may hold to be spliced or sent between processes as it is.
bool only_plain_primitives(const Scene& s);

class SceneFragments final : public PieceConsumer, public FragmentStore {
  public:
    bool consume(size_t piece, const NodeTree& tree, std::span<const NodeId> roots) override;
    // A plain piece (plain_piece.h), built from its tokens.
    std::optional<TextConsumed> consume_text(size_t piece, const PieceText& text) override;
    void discard(size_t piece) override;

    // The fragment of a consumed piece (built, not discarded); null if there is none. The scene
    // build takes its arrays when it frees it afterwards (release), else copies them.
    Scene* fragment(size_t piece) override;
    // Frees a fragment once it is spliced in (build_scene_releasing_tree).
    void release(size_t piece) override { discard(piece); }

    // Pieces built from their tokens so far (tests check that the path is taken).
    size_t text_pieces() const { return text_pieces_; }

  private:
    std::atomic<size_t> text_pieces_{0};
    std::mutex mutex_;
    std::unordered_map<size_t, std::unique_ptr<Scene>> built_;
};

}  // namespace vr
