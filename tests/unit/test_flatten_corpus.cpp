// Every good file of the shared corpus builds and flattens without crashing (folders named bad,
// warnings or errors hold broken files on purpose and are left to the parser's tests).
#include <gtest/gtest.h>

#include <filesystem>

#include "corpus.h"
#include "flatten/flatten.h"
#include "parser/load.h"
#include "scene/build.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> corpus_files(const fs::path& folder) {
    std::vector<fs::path> files;
    if (!fs::is_directory(folder)) return files;
    for (const auto& entry : fs::recursive_directory_iterator(folder)) {
        if (!entry.is_regular_file()) continue;
        const std::string ext = entry.path().extension().string();
        if (ext != ".wrl" && ext != ".x3dv" && ext != ".x3d" && ext != ".gz" && ext != ".x3dz" &&
            ext != ".x3dvz")
            continue;
        bool broken = false;
        for (const fs::path& part : fs::relative(entry.path(), folder))
            if (part == "bad" || part == "warnings" || part == "errors") broken = true;
        if (!broken) files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

void flatten_all(const std::string& subfolder) {
    VR_CORPUS_FOLDER(folder, subfolder);
    const std::vector<fs::path> files = corpus_files(folder);
    ASSERT_FALSE(files.empty()) << "no scene files in " << folder;
    size_t primitives = 0;
    for (const fs::path& file : files) {
        SCOPED_TRACE(file.string());
        LoadedScene loaded = load_scene(file);
        Diagnostics diagnostics;
        const Scene scene = build_scene(loaded, diagnostics);
        FlattenOptions options;
        options.scene_file = loaded.main_file;
        options.allowed_roots = loaded.allowed_roots;
        FlattenStats stats;
        const FlatScene flat = flatten_scene(scene, options, diagnostics, stats);
        primitives += flat.spheres.size() + flat.quadrics.size() + flat.meshes.size();
        // Everything emitted is finite.
        for (const Sphere& s : flat.spheres)
            EXPECT_TRUE(std::isfinite(s.radius) && std::isfinite(s.center.x));
        for (const Mesh& m : flat.meshes)
            for (const Vec3& p : m.positions) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z));
        for (const Shading& s : flat.shadings) {
            ASSERT_LT(s.material, flat.materials.size());
            ASSERT_LT(s.light_set, flat.light_sets.size());
        }
    }
    EXPECT_GT(primitives, 0u);
}

TEST(FlattenCorpus, Vrml97) { flatten_all("vrml97"); }
TEST(FlattenCorpus, X3dClassic) { flatten_all("x3dv"); }
TEST(FlattenCorpus, X3dXml) { flatten_all("x3d"); }
TEST(FlattenCorpus, Vrml1) { flatten_all("vrml1"); }
TEST(FlattenCorpus, Molecular) { flatten_all("molecular"); }

}  // namespace
}  // namespace vr
