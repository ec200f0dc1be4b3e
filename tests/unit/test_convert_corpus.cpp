// Every corpus file that loads survives `convert` to VRML97 and to X3D classic: the tree read back
// equals the original (same nodes, fields, values and sharing; DEF names as the writer makes them
// unique).
#include <gtest/gtest.h>

#include <filesystem>

#include "corpus.h"
#include "parser/load.h"
#include "parser/writer.h"
#include "support/tree_compare.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

TEST(ConvertCorpus, ClassicWritersRoundTripEveryFile) {
    VR_CORPUS_FOLDER(corpus, "");
    size_t files = 0;
    for (const char* folder : {"vrml97", "x3dv", "x3d", "vrml1", "molecular"}) {
        const fs::path dir = corpus / folder;
        ASSERT_TRUE(fs::is_directory(dir)) << dir;
        for (const auto& entry : fs::recursive_directory_iterator(dir)) {
            const std::string name = entry.path().filename().string();
            if (!entry.is_regular_file() ||
                !(name.ends_with(".wrl") || name.ends_with(".gz") || name.ends_with(".x3dv") ||
                  name.ends_with(".x3d") || name.ends_with(".x3dz")))
                continue;
            LoadedScene original = load_scene(entry.path());
            if (!original.ok()) continue;
            for (Encoding target : {Encoding::Vrml97, Encoding::X3dClassic}) {
                // Read back as if it stood where the original does, so that relative Inline URLs
                // still resolve.
                LoadedScene back =
                    load_scene_text(write_classic(original.tree, target), entry.path().string());
                ASSERT_TRUE(back.ok()) << entry.path() << "\n"
                                       << back.diagnostics.format(back.sources);
                if (target == Encoding::Vrml97 && original.tree.root_length_scale != 1.0) {
                    // A UNIT length file (units.x3d) becomes one Transform scaling it all, since
                    // VRML97 has no UNIT: Units.ConvertKeepsTheSizes checks what it draws.
                    EXPECT_EQ(back.tree.roots.size(), 1u) << entry.path();
                    continue;
                }
                // Numbers are written the shortest way that reads back to the same double: exact.
                EXPECT_EQ(compare_trees(original.tree, back.tree, {true, 0.0}), "") << entry.path();
                EXPECT_EQ(back.tree.root_length_scale, original.tree.root_length_scale);
            }
            ++files;
        }
    }
    EXPECT_GE(files,
              155u);  // the corpus holds about 150 loadable scene files and 19 molecular exports
}

}  // namespace
}  // namespace vr
