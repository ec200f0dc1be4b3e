#include "parser/def_names.h"

namespace vr {

DefNames::DefNames(const NodeTree& tree) : tree_(tree) {
    std::vector<NodeId> stack(tree.roots.rbegin(), tree.roots.rend());
    while (!stack.empty()) {
        NodeId id = stack.back();
        stack.pop_back();
        if (id == kNullNode || ++references_[id] > 1) continue;  // a node's fields are walked once
        for (const FieldEntry& e : tree.set_fields(id)) {
            if (e.type.kind != ValueKind::Node) continue;
            for (uint32_t i = 0; i < e.count; ++i) stack.push_back(tree.node_refs[e.begin + i]);
        }
    }
}

uint32_t DefNames::references(NodeId id) const {
    auto it = references_.find(id);
    return it == references_.end() ? 0 : it->second;
}

const std::string& DefNames::name(NodeId id) {
    auto it = names_.find(id);
    if (it != names_.end()) return it->second;
    std::string name(tree_.def_name(id));
    if (name.empty() && references(id) > 1) name = "_shared" + std::to_string(id);
    if (!name.empty()) {
        std::string unique = name;
        for (int k = 2; used_.count(unique); ++k) unique = name + "_" + std::to_string(k);
        used_.insert(unique);
        name = unique;
    }
    return names_.emplace(id, std::move(name)).first->second;
}

}  // namespace vr
