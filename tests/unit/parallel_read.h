// What the tests of reading in pieces (test_parallel_read.cpp: classic; test_parallel_read_xml.cpp:
// X3D XML) compare: a file read by one thread and read in pieces of a forced size.
#pragma once
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "parser/load.h"
#include "support/tree_compare.h"

namespace vr::test {

inline bool same_place(SourceLoc a, SourceLoc b) {
    return a.file == b.file && a.offset == b.offset;
}

// `file` read with VRMLRAY_PIECE_BYTES=`piece` (0: by one thread).
inline LoadedScene load_with_pieces(const std::filesystem::path& file, size_t piece,
                                    const LoadOptions& options = {}) {
    setenv("VRMLRAY_PIECE_BYTES", std::to_string(piece).c_str(), 1);
    LoadedScene scene = load_scene(file, options);
    unsetenv("VRMLRAY_PIECE_BYTES");
    return scene;
}

// "" when the Script nodes' own interfaces (what src/script/ runs) agree: the same Script nodes,
// with the same fields, events, values and text (node ids are equal once the trees are).
inline std::string script_difference(const NodeTree& one, const NodeTree& many) {
    if (one.scripts.size() != many.scripts.size())
        return "Script interfaces: " + std::to_string(one.scripts.size()) + " vs " +
               std::to_string(many.scripts.size());
    for (const auto& [id, a] : one.scripts) {
        const auto it = many.scripts.find(id);
        const std::string which = "Script node " + std::to_string(id);
        if (it == many.scripts.end()) return which + " has no interface in pieces";
        const ScriptInterface& b = it->second;
        if (a.source != b.source || a.fields.size() != b.fields.size()) return which + " differs";
        for (size_t i = 0; i < a.fields.size(); ++i) {
            const ScriptField &fa = a.fields[i], &fb = b.fields[i];
            const FieldView u = one.view(fa.value), v = many.view(fb.value);
            if (fa.name != fb.name || !(fa.type == fb.type) || fa.access != fb.access ||
                !std::equal(u.numbers.begin(), u.numbers.end(), v.numbers.begin(),
                            v.numbers.end()) ||
                !std::equal(u.strings.begin(), u.strings.end(), v.strings.begin(),
                            v.strings.end()) ||
                !std::equal(u.nodes.begin(), u.nodes.end(), v.nodes.begin(), v.nodes.end()))
                return which + " field " + std::string(name_text(fa.name)) + " differs";
        }
    }
    return {};
}

// "" when the two reads agree in everything a user sees of them.
inline std::string difference(const LoadedScene& one, const LoadedScene& many) {
    if (one.tree.nodes.size() != many.tree.nodes.size())
        return "node count " + std::to_string(one.tree.nodes.size()) + " vs " +
               std::to_string(many.tree.nodes.size());
    if (one.tree.roots != many.tree.roots) return "roots differ";
    if (std::string d = compare_trees(one.tree, many.tree); !d.empty()) return d;
    // Places, which later messages (the scene build's) point at: node ids and field entries are
    // in the same order once the trees are equal.
    for (size_t i = 0; i < one.tree.nodes.size(); ++i)
        if (!same_place(one.tree.nodes[i].loc, many.tree.nodes[i].loc))
            return "node " + std::to_string(i) + " has another place";
    if (one.tree.fields.size() != many.tree.fields.size()) return "field entry count differs";
    for (size_t i = 0; i < one.tree.fields.size(); ++i)
        if (!same_place(one.tree.fields[i].loc, many.tree.fields[i].loc))
            return "field entry " + std::to_string(i) + " (" +
                   std::string(name_text(one.tree.fields[i].name)) + ") has another place";
    // The ROUTEs the animator will run: the same nodes and events (node ids are equal once the
    // trees are).
    if (one.tree.routes.size() != many.tree.routes.size()) return "route count differs";
    for (size_t i = 0; i < one.tree.routes.size(); ++i) {
        const Route &a = one.tree.routes[i], &b = many.tree.routes[i];
        if (a.from != b.from || a.to != b.to || a.from_event != b.from_event ||
            a.to_event != b.to_event)
            return "ROUTE " + std::to_string(i) + " differs";
    }
    if (std::string d = script_difference(one.tree, many.tree); !d.empty()) return d;
    const std::string m1 = one.diagnostics.format(one.sources);
    const std::string m2 = many.diagnostics.format(many.sources);
    if (m1 != m2) return "messages differ:\n" + m1 + "---\n" + m2;
    const ReadStats &a = one.stats, &b = many.stats;
    if (a.def_count != b.def_count || a.use_count != b.use_count || a.routes != b.routes ||
        a.proto_instances != b.proto_instances || a.skipped_nodes != b.skipped_nodes ||
        a.proto_declarations != b.proto_declarations || a.inline_files != b.inline_files)
        return "statistics differ";
    if (one.ok() != many.ok()) return "one read failed, the other not";
    return "";
}

}  // namespace vr::test
