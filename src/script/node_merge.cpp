#include "script/node_merge.h"

#include "parser/load.h"

namespace vr {

NodeId append_tree(NodeTree& tree, const NodeTree& from, PackedLoc at) {
    const NodeId base = NodeId(tree.nodes.size());
    const uint32_t numbers = uint32_t(tree.numbers.size()), strings = uint32_t(tree.strings.size()),
                   refs = uint32_t(tree.node_refs.size());
    tree.numbers.insert(tree.numbers.end(), from.numbers.begin(), from.numbers.end());
    tree.strings.insert(tree.strings.end(), from.strings.begin(), from.strings.end());
    for (NodeId r : from.node_refs) tree.node_refs.push_back(r == kNullNode ? kNullNode : r + base);
    for (NodeId id = 0; id < from.nodes.size(); ++id) {
        Node n = from.nodes[id];
        const NodeKind& kind = from.kinds[n.kind];
        n.kind = tree.kind_of(kind.decl, kind.type);
        n.loc = at;
        n.first_field = uint32_t(tree.fields.size());
        for (FieldEntry e : from.set_fields(id)) {
            e.loc = at;
            if (e.type.kind == ValueKind::String)
                e.begin += strings;
            else if (e.type.kind == ValueKind::Node)
                e.begin += refs;
            else
                e.begin += numbers;
            tree.fields.push_back(e);
        }
        tree.add_node(n, from.field_count(id));
    }
    for (const auto& [inline_node, roots] : from.inline_roots) {
        std::vector<NodeId>& moved = tree.inline_roots[inline_node + base];
        for (NodeId r : roots) moved.push_back(r + base);
    }
    for (const auto& [inline_node, scale] : from.inline_length_scale)
        tree.inline_length_scale[inline_node + base] = scale;
    return base;
}

std::vector<NodeId> read_nodes_into(NodeTree& tree, const std::string& text, bool x3d,
                                    const std::filesystem::path& anchor,
                                    const std::vector<std::filesystem::path>& allowed_roots,
                                    PackedLoc at, std::string& error) {
    const size_t first = text.find_first_not_of(" \t\r\n");
    const bool xml = first != std::string::npos && text[first] == '<';
    std::string file;
    if (xml)
        file = text.find("<X3D") != std::string::npos ? text
                                                      : "<X3D><Scene>" + text + "</Scene></X3D>";
    else
        file = (x3d ? "#X3D V3.0 utf8\n" : "#VRML V2.0 utf8\n") + text;
    LoadOptions options;
    if (!allowed_roots.empty()) {
        options.sandbox = true;
        options.sandbox_dir = allowed_roots.front();
        options.allowed_roots = allowed_roots;
    }
    const LoadedScene scene = load_scene_text(std::move(file), anchor.string(), options);
    if (!scene.ok()) {
        for (const Diagnostic& d : scene.diagnostics.all())
            if (d.severity == Severity::Error) {
                error = d.message;
                break;
            }
        if (error.empty()) error = "the text does not read as a scene";
        return {};
    }
    const NodeId base = append_tree(tree, scene.tree, at);
    std::vector<NodeId> roots;
    for (NodeId r : scene.tree.roots) roots.push_back(r + base);
    return roots;
}

}  // namespace vr
