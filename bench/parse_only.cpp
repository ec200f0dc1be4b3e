// Reads one scene with the parser library alone (no scene build, no flattening, no OpenImageIO) and
// prints the reading time, the node count and the process's peak memory; with --dump, a canonical
// listing of the whole node tree and the diagnostics, for checking that two builds read every file
// the same way. Build: -DVRMLRAY_BENCH=ON and `cmake --build BUILD --target parse_only` (it links
// the parser layer alone). Usage: parse_only FILE [--dump]
#include <sys/resource.h>

#include <chrono>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>

#include "parser/load.h"

namespace {

using namespace vr;

void dump_value(const NodeTree& tree, const FieldView& v) {
    if (v.type.kind == ValueKind::Node) {
        for (NodeId id : v.nodes)
            std::printf(" #%" PRId64, id == kNullNode ? int64_t(-1) : int64_t(id));
    } else if (v.type.kind == ValueKind::String) {
        for (const std::string& s : v.strings) std::printf(" \"%s\"", s.c_str());
    } else {
        for (double d : v.numbers) std::printf(" %a", d);
    }
}

void dump(const LoadedScene& scene) {
    const NodeTree& tree = scene.tree;
    std::printf("encoding %s\n", std::string(encoding_name(scene.encoding)).c_str());
    std::printf("roots");
    for (NodeId id : tree.roots) std::printf(" #%u", id);
    std::printf("\n");
    for (NodeId id = 0; id < tree.nodes.size(); ++id) {
        const Node& n = tree.nodes[id];
        std::printf("#%u %s DEF '%s' at %u:%u decl %s\n", id,
                    std::string(tree.type_name(id)).c_str(), std::string(tree.def_name(id)).c_str(),
                    n.loc.get().file, n.loc.get().offset,
                    tree.decl(id) ? std::string(name_text(tree.decl(id)->name)).c_str() : "-");
        for (const FieldEntry& e : tree.set_fields(id)) {
            FieldView v = tree.view(e);
            std::printf("  %s %s at %u:%u =", std::string(name_text(e.name)).c_str(),
                        std::string(type_name(e.type)).c_str(), e.loc.get().file,
                        e.loc.get().offset);
            dump_value(tree, v);
            std::printf("\n");
        }
    }
    for (const auto& [id, roots] : std::map<NodeId, std::vector<NodeId>>(tree.inline_roots.begin(),
                                                                         tree.inline_roots.end())) {
        std::printf("inline #%u ->", id);
        for (NodeId r : roots) std::printf(" #%u", r);
        std::printf("\n");
    }
    const ReadStats& s = scene.stats;
    std::printf(
        "stats def %zu use %zu proto %zu externproto %zu instances %zu inlines %zu routes %zu\n",
        s.def_count, s.use_count, s.proto_declarations, s.externproto_declarations,
        s.proto_instances, s.inline_files, s.routes);
    for (const auto& [type, count] :
         std::map<std::string, size_t>(s.skipped_nodes.begin(), s.skipped_nodes.end()))
        std::printf("skipped %s %zu\n", type.c_str(), count);
    std::printf("%s", scene.diagnostics.format(scene.sources).c_str());
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: parse_only FILE [--dump]\n");
        return 2;
    }
    const bool want_dump = argc > 2 && std::strcmp(argv[2], "--dump") == 0;
    const auto t0 = std::chrono::steady_clock::now();
    LoadedScene scene = load_scene(argv[1]);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (want_dump) {
        dump(scene);
        return 0;
    }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    std::printf("read %.3f s  nodes %zu  errors %zu  peak %.1f MB\n", seconds,
                scene.tree.nodes.size(), scene.diagnostics.error_count(),
                static_cast<double>(usage.ru_maxrss) / 1024.0);
    return scene.ok() ? 0 : 3;
}
