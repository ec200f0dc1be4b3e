// Memory a large scene's build gives back early (issue 16): a pool's front pages, and the node
// tree freed while the scene is built from it. Each must leave every value still to be read as it
// was: the scene built while its tree is freed equals the one built from the whole tree.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "parser/load.h"
#include "parser/node_tree.h"
#include "scene/build.h"
#include "scene/tree_release.h"

namespace vr {
namespace {

size_t resident_bytes() {
    std::ifstream statm("/proc/self/statm");
    size_t total = 0, resident = 0;
    statm >> total >> resident;
    return resident * static_cast<size_t>(sysconf(_SC_PAGESIZE));
}

TEST(TreeRelease, PoolFrontPagesGoBackAndTheRestKeepsItsValues) {
    Pool<double> pool;
    const size_t n = size_t(8) << 20;  // 64 MB: a mapping of its own
    for (size_t i = 0; i < n; ++i) pool.push_back(double(i));
    const size_t before = resident_bytes();
    pool.release_front(n - n / 8);
    const size_t after = resident_bytes();
    // 56 MB were given back in whole 2 MB pages: at least 50 MB must have left, whatever else
    // the test process allocated meanwhile.
    EXPECT_GT(before, after + (size_t(50) << 20));
    ASSERT_EQ(pool.size(), n);
    for (size_t i = n - n / 8; i < n; ++i) ASSERT_EQ(pool[i], double(i)) << i;
    pool.push_back(-1.0);  // still growable
    EXPECT_EQ(pool.back(), -1.0);
}

// A PyMOL-style export of `atoms` atoms (as tools/gen_molecule.py writes them), with radii and
// colours varying so that a value read from a freed page (zero) would show.
std::string molecule(int atoms, const std::string& extra) {
    std::string s = "#VRML V2.0 utf8\n" + extra;
    for (int i = 0; i < atoms; ++i) {
        s += "Transform { translation " + std::to_string(i % 97) + " " + std::to_string(i / 97) +
             " " + std::to_string(i % 13) + ".5 children [ Shape { appearance Appearance { " +
             "material Material { diffuseColor 0." + std::to_string(1 + i % 9) +
             " 0.3 1 specularColor 0.3 0.3 0.3 shininess 0.2 } } geometry Sphere { radius " +
             std::to_string(1 + i % 5) + ".25 } } ] }\n";
    }
    return s;
}

// Fails unless both builds agree; `messages`, if given, gets the build's messages.
void expect_same_scene(const std::string& text, std::string* messages = nullptr) {
    LoadedScene whole = load_scene_text(text, "m.wrl");
    LoadedScene freed = load_scene_text(text, "m.wrl");
    if (!whole.ok() || !freed.ok()) {
        ADD_FAILURE() << whole.diagnostics.format(whole.sources);
        return;
    }
    Diagnostics d1, d2;
    const Scene a = build_scene(whole, d1);
    const Scene b = build_scene_releasing_tree(freed, d2);
    EXPECT_TRUE(freed.tree.nodes.empty());
    if (messages) *messages = d1.format(whole.sources);
    ASSERT_EQ(a.groups.size(), b.groups.size());
    ASSERT_EQ(a.translations.size(), b.translations.size());
    for (size_t i = 0; i < a.translations.size(); ++i)
        ASSERT_EQ(a.translations[i], b.translations[i]) << i;
    ASSERT_EQ(a.child_refs.size(), b.child_refs.size());
    for (size_t i = 0; i < a.groups.size(); ++i) {
        ASSERT_EQ(a.groups[i].child_count, b.groups[i].child_count) << i;
        ASSERT_EQ(a.groups[i].origin.loc.get().offset, b.groups[i].origin.loc.get().offset) << i;
    }
    ASSERT_EQ(a.shapes.size(), b.shapes.size());
    for (size_t i = 0; i < a.shapes.size(); ++i) {
        ASSERT_EQ(a.shapes[i].geometry, b.shapes[i].geometry) << i;
        ASSERT_EQ(a.shapes[i].appearance, b.shapes[i].appearance) << i;
    }
    ASSERT_EQ(a.materials.size(), b.materials.size());
    for (size_t i = 0; i < a.materials.size(); ++i)
        ASSERT_EQ(a.materials[i].diffuse_color, b.materials[i].diffuse_color) << i;
    ASSERT_EQ(a.geometries.size(), b.geometries.size());
    for (size_t i = 0; i < a.geometries.size(); ++i) {
        const auto* sa = std::get_if<sg::Sphere>(&a.geometries[i].shape);
        const auto* sb = std::get_if<sg::Sphere>(&b.geometries[i].shape);
        ASSERT_EQ(sa == nullptr, sb == nullptr) << i;
        if (sa) {
            ASSERT_EQ(sa->radius, sb->radius) << i;
        }
    }
    EXPECT_EQ(d1.format(whole.sources), d2.format(freed.sources));
}

TEST(TreeRelease, ASceneBuiltWhileItsTreeIsFreedEqualsTheWholeTreesScene) {
    // 30,000 top-level nodes: several release steps (TreeRelease::kStep) over pools that are
    // mappings; a bad Sphere last, whose warning must still name its place.
    static_assert(detail::TreeRelease::kStep < 30000 / 4);
    expect_same_scene(molecule(30000, "") + "Shape { geometry Sphere { radius -1 } }\n");
}

TEST(TreeRelease, PrototypeDefaultsStoredEarlyAreStillReadLate) {
    // A PROTO's default lives where its declaration was read, at the file's start; the instances
    // at the end read it there.
    const std::string proto =
        "PROTO Atom [ field SFVec3f at 7 8 9 ] { Transform { translation IS at children Shape "
        "{ geometry Sphere { radius 2 } } } }\n";
    expect_same_scene(molecule(40000, proto) + "Atom { }\nAtom { at 1 2 3 }\n");
}

}  // namespace
}  // namespace vr
