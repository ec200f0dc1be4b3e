#include "scene/tree_release.h"

#include <algorithm>

namespace vr::detail {

void TreeRelease::Low::merge(const Low& o) {
    node = std::min(node, o.node);
    field = std::min(field, o.field);
    number = std::min(number, o.number);
    ref = std::min(ref, o.ref);
}

TreeRelease::Low TreeRelease::subtree_low(NodeId root, std::vector<NodeId>& stack) const {
    // Every index the builder can read for this subtree: its nodes, their field entries, and
    // what those entries point at (wherever the reader put it, e.g. a PROTO default's values).
    Low low;
    stack.assign(1, root);
    while (!stack.empty()) {
        const NodeId id = stack.back();
        stack.pop_back();
        if (id >= tree_->nodes.size()) continue;  // kNullNode
        low.node = std::min<size_t>(low.node, id);
        const std::span<const FieldEntry> fields = tree_->set_fields(id);
        if (!fields.empty()) low.field = std::min<size_t>(low.field, tree_->nodes[id].first_field);
        for (const FieldEntry& e : fields) {
            if (e.count == 0 || e.type.kind == ValueKind::String) continue;  // strings stay
            if (e.type.kind != ValueKind::Node) {
                low.number = std::min<size_t>(low.number, e.begin);
                continue;
            }
            low.ref = std::min<size_t>(low.ref, e.begin);
            for (uint32_t i = 0; i < e.count; ++i) stack.push_back(tree_->node_refs[e.begin + i]);
        }
    }
    return low;
}

TreeRelease::TreeRelease(NodeTree& tree, bool shared) {
    // Inline contents hang off a map, not the fields: keep such a tree whole (it is small).
    if (shared || !tree.inline_roots.empty() || tree.roots.size() <= kStep) return;
    tree_ = &tree;
    const size_t n = tree.roots.size();
    after_.resize((n + kStep - 1) / kStep + 1);  // the last one: nothing after the end
    std::vector<NodeId> stack;
    Low low;
    for (size_t k = n; k-- > 0;) {
        low.merge(subtree_low(tree.roots[k], stack));
        if (k % kStep == 0) after_[k / kStep] = low;
    }
}

void TreeRelease::built(size_t k) {
    if (!tree_ || (k + 1) % kStep != 0) return;
    const Low& low = after_[(k + 1) / kStep];
    // SIZE_MAX (nothing later reads the pool) releases it whole.
    tree_->nodes.release_front(low.node);
    tree_->fields.release_front(low.field);
    tree_->numbers.release_front(low.number);
    tree_->node_refs.release_front(low.ref);
}

}  // namespace vr::detail
