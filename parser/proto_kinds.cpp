#include "parser/proto_kinds.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <unordered_set>

namespace vr {

namespace {

std::unordered_set<NodeId> named_by_events(const NodeTree& tree) {
    std::unordered_set<NodeId> out;
    for (const Route& r : tree.routes) out.insert({r.from, r.to});
    for (const IsLink& l : tree.is_links) out.insert({l.instance, l.node});
    for (const Export& e : tree.exports) out.insert(e.node);
    for (const Import& i : tree.imports) out.insert(i.node);
    return out;
}

// A node a PROTO body may hold a copy of: one of the small appearance and primitive nodes, with
// nodes of the same sort below it.
bool copyable(const NodeTree& tree, NodeId id, const std::unordered_set<NodeId>& fixed) {
    if (id == kNullNode) return true;
    static const std::string_view kTypes[] = {
        "Shape", "Appearance", "Material", "TwoSidedMaterial", "Sphere", "Cylinder", "Cone", "Box"};
    const std::string_view type = tree.type_name(id);
    if (std::find(std::begin(kTypes), std::end(kTypes), type) == std::end(kTypes)) return false;
    if (fixed.count(id)) return false;
    for (const FieldEntry& e : tree.set_fields(id)) {
        if (e.type.kind != ValueKind::Node) continue;
        for (uint32_t i = 0; i < e.count; ++i)
            if (!copyable(tree, tree.node_refs[e.begin + i], fixed)) return false;
    }
    return true;
}

// The Transform's value but for its translation, as text: field names, number bits, the child's
// id (identical Shapes are one node by now: app/compact_scene.h, share_identical_nodes). Empty
// when the Transform does not qualify (proto_kinds.h).
std::string kind_key(const NodeTree& tree, NodeId id, const DefNames& names,
                     const std::unordered_set<NodeId>& fixed) {
    if (tree.type_name(id) != "Transform" || names.references(id) != 1 ||
        !tree.def_name(id).empty() || fixed.count(id))
        return {};
    static const std::string_view kFields[] = {"translation",      "rotation", "scale",
                                               "scaleOrientation", "center",   "children"};
    std::vector<const FieldEntry*> fields;
    NodeId child = kNullNode;
    for (const FieldEntry& e : tree.set_fields(id)) {
        const std::string_view name = name_text(e.name);
        if (std::find(std::begin(kFields), std::end(kFields), name) == std::end(kFields)) return {};
        if (name == "children") {
            if (e.count != 1) return {};
            child = tree.node_refs[e.begin];
        } else if (name != "translation") {
            fields.push_back(&e);
        }
    }
    if (child == kNullNode || tree.type_name(child) != "Shape" || !copyable(tree, child, fixed))
        return {};
    std::sort(fields.begin(), fields.end(), [](const FieldEntry* a, const FieldEntry* b) {
        return name_text(a->name) < name_text(b->name);
    });
    std::string key(reinterpret_cast<const char*>(&child), sizeof child);
    for (const FieldEntry* e : fields) {
        key += name_text(e->name);
        key += '\0';
        for (double x : tree.view(*e).numbers) {
            const uint64_t bits = std::bit_cast<uint64_t>(x + 0.0);
            key.append(reinterpret_cast<const char*>(&bits), sizeof bits);
        }
    }
    return key;
}

}  // namespace

std::string proto_kind_name(size_t k) {
    std::string name(1, char('A' + k % 26));
    if (k >= 26) name += std::to_string(k / 26);
    return name;
}

ProtoKinds find_proto_kinds(const NodeTree& tree, const DefNames& names) {
    const std::unordered_set<NodeId> fixed = named_by_events(tree);
    // In the order the writer meets them, so that the first kind written is A.
    std::vector<NodeId> order;
    std::unordered_set<NodeId> seen;
    std::vector<NodeId> stack(tree.roots.rbegin(), tree.roots.rend());
    while (!stack.empty()) {
        const NodeId id = stack.back();
        stack.pop_back();
        if (id == kNullNode || !seen.insert(id).second) continue;
        order.push_back(id);
        const auto fields = tree.set_fields(id);
        for (auto e = fields.rbegin(); e != fields.rend(); ++e)
            if (e->type.kind == ValueKind::Node)
                for (uint32_t i = e->count; i-- > 0;) stack.push_back(tree.node_refs[e->begin + i]);
    }
    std::unordered_map<std::string, std::vector<NodeId>> groups;
    std::vector<const std::vector<NodeId>*> in_order;
    for (NodeId id : order) {
        std::string key = kind_key(tree, id, names, fixed);
        if (key.empty()) continue;
        std::vector<NodeId>& members = groups[std::move(key)];
        if (members.empty()) in_order.push_back(&members);
        members.push_back(id);
    }
    ProtoKinds kinds;
    for (const std::vector<NodeId>* members : in_order) {
        if (members->size() < 2) continue;  // a declaration costs more than one Transform
        const uint32_t k = uint32_t(kinds.bodies.size());
        kinds.names.push_back(proto_kind_name(k));
        kinds.bodies.push_back(members->front());
        for (NodeId id : *members) kinds.kind_of[id] = k;
    }
    return kinds;
}

void keep_kinds_that_pay(
    ProtoKinds& kinds,
    const std::function<KindCost(size_t kind, size_t members, const std::string& name)>& cost) {
    ProtoKinds kept;
    std::vector<size_t> members(kinds.bodies.size());
    for (const auto& [id, k] : kinds.kind_of) ++members[k];
    for (size_t k = 0; k < kinds.bodies.size(); ++k) {
        const std::string name = proto_kind_name(kept.bodies.size());
        const KindCost c = cost(k, members[k], name);
        if (c.declared >= c.plain) continue;
        for (const auto& [id, kind] : kinds.kind_of)
            if (kind == k) kept.kind_of[id] = uint32_t(kept.bodies.size());
        kept.names.push_back(name);
        kept.bodies.push_back(kinds.bodies[k]);
    }
    kinds = std::move(kept);
}

}  // namespace vr
