// flatten_scene_releasing (src/flatten/release.cpp): the typed scene's per-node chunks freed behind
// the walk over the root's children. The flat scene must be the one flatten_scene makes, bit for
// bit, and the chunks must actually go where the scene allows it (a subtree per atom, none
// shared), and stay where it does not (a group USEd by two of the root's children).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "flatten/flatten.h"
#include "parser/load.h"
#include "scene/build.h"
#include "scene/chunked_array.h"
#include "scene/fragments.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

TEST(ChunkedArray, ReleaseBelowFreesOnlyWholeChunksBeforeTheBound) {
    ChunkedArray<int> c;
    c.push_back(0);
    c.push_back(1);
    c.push_back(2);
    c.adopt({3, 4, 5});
    c.adopt({6, 7});
    c.adopt({8});
    const size_t before = c.held_bytes();
    // Chunk [0, 3) holds the kept index 0; [3, 6) ends at the bound; [6, 8) does not.
    EXPECT_EQ(c.release_below(6, 0), 3 * sizeof(int));
    EXPECT_EQ(c.held_bytes(), before - 3 * sizeof(int));
    for (int i : {0, 1, 2, 6, 7, 8}) EXPECT_EQ(c[size_t(i)], i) << i;
    // The last chunk stays whatever the bound (it is the one that grows).
    EXPECT_EQ(c.release_below(100, 0), 2 * sizeof(int));
    EXPECT_EQ(c[8], 8);
    EXPECT_EQ(c.size(), 9u);
    EXPECT_EQ(c.release_below(100, 0), 0u);
}

struct TempFile {  // a name of this process's own: CTest runs the tests in parallel processes
    fs::path path;
    explicit TempFile(const std::string& text)
        : path(test::temp_path("vrmlray_release").string() + ".wrl") {
        std::ofstream(path) << text;
    }
    ~TempFile() { fs::remove(path); }
};

// A PyMOL-style export of n atoms (plus, with `shared`, one group USEd by the first and the last
// of the root's children).
std::string molecule(int n, bool shared) {
    std::string s = "#VRML V2.0 utf8\nViewpoint { position 0 0 80 }\n";
    if (shared)
        s += "DEF SHARED Transform { translation 0 0 -5 children Shape { geometry Sphere {} } }\n";
    for (int i = 0; i < n; ++i)
        s += "Transform { translation " + std::to_string(i % 37 - 18) + "." +
             std::to_string(i % 10) + " " + std::to_string(i % 23 - 11) + " " +
             std::to_string(i % 5) +
             " children [ Shape { appearance Appearance { material Material { diffuseColor 0." +
             std::to_string(i % 9) + " 0.5 1 } } geometry Sphere { radius 0." +
             std::to_string(3 + i % 5) + " } } ] }\n";
    if (shared) s += "USE SHARED\n";
    return s;
}

// The typed scene of `file` read in small pieces (so that its nodes lie in many chunks).
Scene scene_in_pieces(const fs::path& file) {
    setenv("VRMLRAY_PIECE_BYTES", "65536", 1);
    LoadOptions options;
    options.piece_consumer = std::make_shared<SceneFragments>();
    LoadedScene loaded = load_scene(file, options);
    unsetenv("VRMLRAY_PIECE_BYTES");
    Diagnostics d;
    Scene scene = build_scene(loaded, d);
    EXPECT_FALSE(d.has_errors());
    return scene;
}

size_t node_bytes(const Scene& s) {
    return s.groups.held_bytes() + s.shapes.held_bytes() + s.translations.held_bytes() +
           s.child_refs.held_bytes() + s.translated_shapes.held_bytes();
}

void expect_same_spheres(const FlatScene& a, const FlatScene& b) {
    ASSERT_EQ(a.spheres.size(), b.spheres.size());
    for (size_t i = 0; i < a.spheres.size(); ++i) {
        const Sphere &x = a.spheres[i], &y = b.spheres[i];
        ASSERT_TRUE(x.center == y.center && x.radius == y.radius && x.shading == y.shading &&
                    x.gas == y.gas)
            << i;
    }
    EXPECT_EQ(a.materials.size(), b.materials.size());
    EXPECT_EQ(a.shadings.size(), b.shadings.size());
    EXPECT_EQ(a.lights.size(), b.lights.size());
}

TEST(FlattenRelease, AMoleculesTypedNodesGoAndItsFlatSceneIsTheSame) {
    // 20,000 atoms: five releases (one every 4,096 of the root's children).
    const TempFile file(molecule(20000, false));
    const Scene kept = scene_in_pieces(file.path);
    Scene released = scene_in_pieces(file.path);
    const size_t before = node_bytes(released);
    // Each atom is a record (sg::TranslatedShape), and the root's block refers to it.
    const size_t records = released.translated_shapes.held_bytes();
    EXPECT_GE(records, 20000 * sizeof(sg::TranslatedShape));
    FlattenOptions options;
    Diagnostics d1, d2;
    FlattenStats s1, s2;
    const FlatScene a = flatten_scene(kept, options, d1, s1);
    const FlatScene b = flatten_scene_releasing(released, options, d2, s2);
    EXPECT_EQ(a.spheres.size(), 20000u);
    expect_same_spheres(a, b);
    // Everything before the last release's atom (16,384 of 20,000) and its chunk may go; the
    // root's block stays (the walk reads it to the end).
    EXPECT_LT(released.translated_shapes.held_bytes(), records / 3) << records;
    EXPECT_LE(node_bytes(released), before - (records - released.translated_shapes.held_bytes()));
}

TEST(FlattenRelease, AGroupUsedByTwoOfTheRootsChildrenKeepsEveryNode) {
    const TempFile file(molecule(10000, true));
    const Scene kept = scene_in_pieces(file.path);
    Scene released = scene_in_pieces(file.path);
    const size_t before = node_bytes(released);
    FlattenOptions options;
    Diagnostics d1, d2;
    FlattenStats s1, s2;
    const FlatScene a = flatten_scene(kept, options, d1, s1);
    const FlatScene b = flatten_scene_releasing(released, options, d2, s2);
    EXPECT_EQ(a.spheres.size(), 10002u);  // the shared sphere twice
    expect_same_spheres(a, b);
    EXPECT_EQ(node_bytes(released), before);
}

}  // namespace
}  // namespace vr
