// vrmlray convert IN OUT: rewrite a scene in the encoding OUT's extension names.
#include <zlib.h>

#include <fstream>
#include <iostream>

#include "app/commands.h"
#include "app/compact_scene.h"
#include "app/pipeline.h"
#include "app/scene_files.h"
#include "parser/writer.h"
#include "parser/xml_writer.h"

namespace vr {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() &&
           s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

struct Target {
    Encoding encoding = Encoding::Unknown;
    bool gzip = false;
};

Target target_for(std::string name) {
    for (char& ch : name) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    Target t;
    if (ends_with(name, ".gz")) {
        t.gzip = true;
        name.resize(name.size() - 3);
    }
    if (const SceneExtension* e = scene_extension_of(name)) {
        t.encoding = e->encoding;
        t.gzip = t.gzip || e->gzip;
    }
    return t;
}

bool write_output(const std::string& path, const std::string& text, bool gzip) {
    if (gzip) {
        gzFile f = gzopen(path.c_str(), "wb9");
        if (!f) return false;
        bool ok = text.empty() || gzwrite(f, text.data(), static_cast<unsigned>(text.size())) > 0;
        return gzclose(f) == Z_OK && ok;
    }
    std::ofstream out(path, std::ios::binary);
    out << text;
    out.close();
    return static_cast<bool>(out);
}

// What --recover-spheres made of the tree: the mesh nodes that became exact ones, why the others
// did not (the renderer's reasons, as `vrmlray info` gives them), and the nodes shared.
void print_compact_stats(const CompactStats& c, size_t bytes) {
    std::cerr << "recovered " << c.spheres << " spheres and " << c.cylinders << " cylinders of "
              << c.meshes << " mesh nodes; " << c.shared << " identical nodes shared; " << bytes
              << " bytes\n";
    for (size_t m = 0; m < c.misses.size(); ++m)
        if (c.misses[m] > 0)
            std::cerr << "  " << c.misses[m]
                      << " mesh nodes not recovered: " << recovery_miss_label(RecoveryMiss(m))
                      << "\n";
}

}  // namespace

int run_convert(const std::string& in, const std::string& out, const CommonOptions& common,
                const ConvertOptions& options) {
    Target target = target_for(out);
    if (target.encoding == Encoding::Unknown) {
        std::string plain_names = scene_extension_names(false, ", ");  // ".wrl, .x3dv or .x3d"
        plain_names.replace(plain_names.rfind(", "), 2, " or ");
        std::cerr << "vrmlray: error: cannot tell the output encoding from '" << out << "': use "
                  << plain_names << " (optionally .gz, or " << scene_extension_names(true, "/")
                  << ")\n";
        return kExitUsage;
    }
    LoadedScene scene;
    if (!load_and_report(in, common, scene)) return kExitBadInput;
    CompactStats compact;
    if (options.recover) {
        recover_exact_nodes(scene.tree, compact);
        share_identical_nodes(scene.tree, compact);
    }
    std::string text = target.encoding == Encoding::X3dXml
                           ? write_x3d_xml(scene.tree, options.recover)
                           : write_classic(scene.tree, target.encoding, options.recover);
    if (!write_output(out, text, target.gzip)) {
        std::cerr << out << ": error: cannot write the output file\n";
        return kExitOutput;
    }
    if (!common.quiet)
        std::cerr << "wrote " << out << " (" << encoding_name(target.encoding)
                  << (target.gzip ? ", gzip" : "") << ", " << scene.tree.nodes.size()
                  << " nodes read)\n";
    if (!common.quiet && options.recover) print_compact_stats(compact, text.size());
    return kExitOk;
}

}  // namespace vr
