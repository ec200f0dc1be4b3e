// The node tree's packed records: a Node names its (interface, type) through NodeTree::kinds, and a
// FieldEntry keeps its type in one byte and its place in seven (an 18-bit file index, a 38-bit
// offset). Places must come back exact, also in files other than the first.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "parser/load.h"
#include "parser/registry.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

TEST(NodeTreePacking, PackedLocRoundTripsEdges) {
    EXPECT_FALSE(PackedLoc{}.valid());
    EXPECT_FALSE(PackedLoc(SourceLoc{}).valid());
    EXPECT_EQ(PackedLoc(SourceLoc{}).get().file, UINT32_MAX);  // "no place" stays SourceLoc's
    for (SourceLoc loc : {SourceLoc{0, 0}, SourceLoc{1, 0xffffffffu}, SourceLoc{5, 0x12345678u},
                          SourceLoc{SourceManager::kMaxFiles - 1, 0x80000000u}}) {
        const SourceLoc back = PackedLoc(loc);
        EXPECT_EQ(back.file, loc.file);
        EXPECT_EQ(back.offset, loc.offset);
        EXPECT_TRUE(back.valid());
    }
}

TEST(NodeTreePacking, FieldTypeInOneByteKeepsEveryKind) {
    for (int k = 0; k <= static_cast<int>(ValueKind::Matrix4d); ++k)
        for (bool multi : {false, true}) {
            const FieldType t{static_cast<ValueKind>(k), multi};
            EXPECT_EQ(static_cast<int>(t.kind), k);
            EXPECT_EQ(t.multi, multi);
            // The packed byte still names the type the readers and writers spell (SFVec3f,
            // MFNode...).
            const std::optional<FieldType> back = parse_type_name(type_name(t));
            ASSERT_TRUE(back.has_value()) << k << " " << multi;
            EXPECT_EQ(*back, t);
            // Filling the fields packed around it (all bits set) leaves the type alone.
            FieldEntry e;
            e.type = t;
            e.name = Name(~0u);
            e.loc = PackedLoc(SourceLoc{SourceManager::kMaxFiles - 1, 0xffffffffu});
            e.begin = e.count = 0xffffffffu;
            EXPECT_EQ(e.type, t);
        }
    EXPECT_EQ(FieldType{}.kind, ValueKind::Float);  // the default stays SFFloat
    EXPECT_FALSE(FieldType{}.multi);
}

TEST(NodeTreePacking, NodesOfOneKindShareAnEntry) {
    LoadedScene s = load_scene_text(
        "#VRML V2.0 utf8\n"
        "Transform { children [ Shape { geometry Sphere {} } ] }\n"
        "Transform { children [ Shape { geometry Sphere {} } ] }\n"
        "Shape { geometry Box {} }\n",
        (vr::test::temp_path("kinds") / "kinds.wrl").string());
    ASSERT_TRUE(s.ok()) << s.diagnostics.format(s.sources);
    EXPECT_EQ(s.tree.nodes.size(), 8u);
    EXPECT_EQ(s.tree.kinds.size(), 5u);  // (none), Sphere, Shape, Transform, Box
    for (NodeId id = 0; id < s.tree.nodes.size(); ++id) {
        ASSERT_NE(s.tree.decl(id), nullptr);
        EXPECT_EQ(s.tree.decl(id)->name, s.tree.type(id));
    }
    EXPECT_EQ(s.tree.type_name(s.tree.roots.back()), "Shape");
}

// Regression guard for the packed place: a field read from the second of three Inline files
// reports that file and its own line and column.
TEST(NodeTreePacking, FieldPlaceInSecondInlineFileIsExact) {
    const fs::path dir = vr::test::temp_path("vrmlray_test_packing");
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir / name, std::ios::binary) << text;
    };
    write("a.wrl", "#VRML V2.0 utf8\nShape { geometry Sphere { radius 1 } }\n");
    write("b.wrl", "#VRML V2.0 utf8\n\n\nShape {\n  geometry Sphere {\n      radius 2.5 } }\n");
    write("c.wrl", "#VRML V2.0 utf8\nShape { geometry Sphere { radius 3 } }\n");
    write("main.wrl",
          "#VRML V2.0 utf8\nInline { url \"a.wrl\" }\nInline { url \"b.wrl\" }\n"
          "Inline { url \"c.wrl\" }\n");
    LoadedScene s = load_scene(dir / "main.wrl");
    ASSERT_TRUE(s.ok()) << s.diagnostics.format(s.sources);
    ASSERT_EQ(s.sources.size(), 4u);
    const Name sphere = intern("Sphere"), radius = intern("radius");
    int seen = 0;
    for (NodeId id = 0; id < s.tree.nodes.size(); ++id) {
        if (s.tree.type(id) != sphere) continue;
        const FieldView v = s.tree.get(id, radius);
        ASSERT_FALSE(v.is_default);
        ASSERT_TRUE(v.loc.valid());
        if (v.numbers[0] != 2.5) continue;
        ++seen;
        EXPECT_EQ(fs::path(s.sources.file(v.loc.file).path).filename(), "b.wrl");
        const LineCol lc = s.sources.line_col(v.loc);
        EXPECT_EQ(lc.line, 6u);
        EXPECT_EQ(lc.column, 14u);  // the value, after "      radius "
        const SourceLoc node = s.tree.nodes[id].loc;
        EXPECT_EQ(node.file, v.loc.file);
        EXPECT_EQ(s.sources.line_col(node).line, 5u);
    }
    EXPECT_EQ(seen, 1);
    fs::remove_all(dir);
}

// A node keeps its field count in one byte; 255 and more go to NodeTree::many_fields.
TEST(NodeTreePacking, FieldCountsAroundTheOneByteEdge) {
    NodeTree tree;
    std::vector<NodeId> ids;
    for (uint32_t count : {0u, 1u, 254u, 255u, 256u, 70000u, 3u}) {
        Node n;
        n.first_field = static_cast<uint32_t>(tree.fields.size());
        for (uint32_t i = 0; i < count; ++i) {
            FieldEntry e;
            e.name = static_cast<Name>(1000 + i);
            tree.fields.push_back(e);
        }
        ids.push_back(tree.add_node(n, count));
    }
    const uint32_t expected[] = {0, 1, 254, 255, 256, 70000, 3};
    for (size_t i = 0; i < ids.size(); ++i) {
        EXPECT_EQ(tree.field_count(ids[i]), expected[i]);
        const auto set = tree.set_fields(ids[i]);
        ASSERT_EQ(set.size(), expected[i]);
        if (!set.empty()) {
            EXPECT_EQ(set.back().name, static_cast<Name>(1000 + expected[i] - 1));
        }
    }
    EXPECT_EQ(tree.many_fields.size(), 3u);
}

}  // namespace
}  // namespace vr
