#include "parser/node_tree.h"

#include "parser/field_value.h"
#include "parser/registry.h"

namespace vr {

size_t FieldView::size() const {
    if (type.kind == ValueKind::Node) return nodes.size();
    if (type.kind == ValueKind::String) return strings.size();
    if (type.kind == ValueKind::Image) {
        // Images are variable-length: walk them.
        size_t n = 0, i = 0;
        while (i + 3 <= numbers.size()) {
            i += 3 + static_cast<size_t>(numbers[i] * numbers[i + 1]);
            ++n;
        }
        return n;
    }
    return numbers.size() / static_cast<size_t>(components(type.kind));
}

static FieldView view_in(const NodeTree& tree, const FieldEntry& e, bool is_default) {
    FieldView v;
    v.type = e.type;
    v.loc = e.loc;
    v.is_default = is_default;
    v.found = true;
    if (e.type.kind == ValueKind::Node) {
        v.nodes = {tree.node_refs.data() + e.begin, e.count};
    } else if (e.type.kind == ValueKind::String) {
        v.strings = {tree.strings.data() + e.begin, e.count};
    } else {
        v.numbers = {tree.numbers.data() + e.begin, e.count};
    }
    return v;
}

NodeId NodeTree::add_node(Node n, uint32_t field_count) {
    const auto id = static_cast<NodeId>(nodes.size());
    if (field_count >= Node::kManyFields) {
        n.few_fields = Node::kManyFields;
        many_fields[id] = field_count;
    } else {
        n.few_fields = static_cast<uint8_t>(field_count);
    }
    nodes.push_back(n);
    return id;
}

uint32_t NodeTree::kind_of(const NodeTypeDecl* decl, Name type) {
    const uint64_t key = (reinterpret_cast<uintptr_t>(decl) >> 3) ^ (uint64_t(type) << 40);
    uint32_t& cached = kind_cache_[(key * 0x9E3779B97F4A7C15ull) >> 58];
    if (kinds[cached].decl == decl && kinds[cached].type == type) return cached;
    std::vector<uint32_t>& same_key = kind_index_[key];
    for (uint32_t k : same_key)
        if (kinds[k].decl == decl && kinds[k].type == type) return cached = k;
    const auto k = static_cast<uint32_t>(kinds.size());
    kinds.push_back({decl, type});
    same_key.push_back(k);
    return cached = k;
}

void NodeTree::clear_keeping_memory() {
    nodes.clear();
    kinds.assign(1, NodeKind{});
    fields.clear();
    numbers.clear();
    strings.clear();
    node_refs.clear();
    roots.clear();
    many_fields.clear();
    routes.clear();
    is_links.clear();
    exports.clear();
    imports.clear();
    scripts.clear();
    inline_roots.clear();
    root_length_scale = 1.0;
    inline_length_scale.clear();
    kind_cache_.fill(0);
    kind_index_.clear();
}

FieldView NodeTree::view(const FieldEntry& entry) const { return view_in(*this, entry, false); }

FieldView NodeTree::get(NodeId id, Name field) const {
    const Node& n = nodes[id];
    for (const FieldEntry& e : set_fields(id))
        if (e.name == field) return view_in(*this, e, false);
    const NodeTypeDecl* type = kinds[n.kind].decl;
    if (!type) return {};
    const Registry& reg = Registry::builtin();
    const FieldDecl* decl = reg.lookup_field(type->spec, *type, field);
    if (!decl || decl->default_field == UINT32_MAX) return {};
    const NodeTree& defaults = *decl->default_tree;
    return view_in(defaults, defaults.fields[decl->default_field], true);
}

FieldView NodeTree::get(NodeId node, std::string_view field) const {
    return get(node, intern(field));
}

bool NodeTree::get_bool(NodeId node, Name field) const {
    FieldView v = get(node, field);
    return !v.numbers.empty() && v.numbers[0] != 0.0;
}

int32_t NodeTree::get_int(NodeId node, Name field) const {
    FieldView v = get(node, field);
    return v.numbers.empty() ? 0 : int32_of_number(v.numbers[0], -1);
}

double NodeTree::get_number(NodeId node, Name field) const {
    FieldView v = get(node, field);
    return v.numbers.empty() ? 0.0 : v.numbers[0];
}

NodeId NodeTree::get_node(NodeId node, Name field) const {
    FieldView v = get(node, field);
    return v.nodes.empty() ? kNullNode : v.nodes[0];
}

}  // namespace vr
