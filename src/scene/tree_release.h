// Gives a node tree's memory back while the scene is built from it, top-level node by top-level
// node, so that a large scene's peak is not the whole tree and the whole typed scene at once.
// Private to src/scene (build_scene_releasing_tree).
#pragma once
#include <cstddef>
#include <vector>

#include "parser/node_tree.h"

namespace vr::detail {

class TreeRelease {
  public:
    // Top-level nodes are released in groups of this many (a few megabytes of tree).
    static constexpr size_t kStep = 4096;

    // Plans the release of `tree`, whose nodes are built from `tree.roots` in order and each only
    // through the fields of the top-level node it stands under. `shared` says the tree has nodes
    // referred to twice (DEF/USE), which later top-level nodes may reach: nothing is released.
    TreeRelease(NodeTree& tree, bool shared);
    bool active() const { return tree_ != nullptr; }
    // Top-level nodes roots[0..k] are built: what no later one reads goes back to the kernel.
    void built(size_t k);

  private:
    // The lowest index into each pool that the subtrees of some top-level nodes read.
    struct Low {
        size_t node = SIZE_MAX, field = SIZE_MAX, number = SIZE_MAX, ref = SIZE_MAX;
        void merge(const Low& o);
    };
    Low subtree_low(NodeId root, std::vector<NodeId>& stack) const;

    NodeTree* tree_ = nullptr;
    std::vector<Low> after_;  // after_[j]: the lowest of roots[j * kStep ..]
};

}  // namespace vr::detail
