// The wire form of a plain piece's scene fragment (src/app/fragment_wire.h), which processes that
// split a file's reading send each other (docs/mpi.md "Split reading"): what arrives must be the
// fragment that left, array for array and field for field, so that every process splices the
// same scene; a piece that is not plain arrives as such; a cut message is refused, not misread.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "app/fragment_wire.h"
#include "scene/plain_piece.h"

namespace vr {
namespace {

// Every node type and transform kind a plain piece makes, the atoms' records (sg::TranslatedShape),
// and a Shape and a record whose Appearance is a USE of a DEF before the piece (an outer node,
// resolved where the piece joins).
const std::string kPiece = R"(Transform { translation 1 2 3 children Shape {
  appearance Appearance { material Material { diffuseColor 0.2 0.4 0.6 shininess 0.3 } }
  geometry Sphere { radius 0.75 } } }
Transform { translation 0 1 0 rotation 1 0 0 0.5 children Shape {
  appearance Appearance { material Material { diffuseColor 0.2 0.4 0.6 shininess 0.3 } }
  geometry Cylinder { radius 0.1 height 2 top FALSE } } }
Group { children [ Shape { appearance USE ATOM_GREY geometry Box { size 1 2 3 } }
  Shape { geometry Cone { bottomRadius 0.5 height 1 } } ] }
Transform { translation 4 5 6 children Shape { appearance USE ATOM_GREY
  geometry Sphere { radius 0.75 } } }
)";

PlainPiece read(const std::string& text) {
    const PieceText piece{text, 0, 0, uint32_t(text.size()), Spec::Vrml97, 1000000, 1000, 1 << 20};
    std::optional<PlainPiece> plain = read_plain_piece(piece);
    if (!plain) throw std::logic_error("the test's piece is not plain");
    return std::move(*plain);
}

void expect_same_origin(const sg::Origin& a, const sg::Origin& b) {
    EXPECT_EQ(a.type_text(), b.type_text());
    EXPECT_EQ(a.def_text(), b.def_text());
    EXPECT_EQ(a.loc.get().file, b.loc.get().file);
    EXPECT_EQ(a.loc.get().offset, b.loc.get().offset);
}

TEST(FragmentWire, APlainPieceArrivesAsItLeft) {
    const PlainPiece plain = read(kPiece);
    const Scene& s = plain.fragment;
    ASSERT_TRUE(fits_wire(s));
    ASSERT_EQ(s.matrices.size(), 1u);           // the rotated Transform
    ASSERT_EQ(s.translated_shapes.size(), 2u);  // the first and the last Transform
    ASSERT_EQ(s.geometries.size(), 4u);
    ASSERT_EQ(plain.counts.outer_uses.size(), 1u);

    std::vector<WirePiece> out(2);
    out[0].piece = 7;
    out[0].fragment = read(kPiece).fragment;
    out[0].counts = plain.counts;
    out[1].piece = 9;  // not plain
    const std::vector<WirePiece> in = unpack_pieces(pack_pieces(out));
    ASSERT_EQ(in.size(), 2u);
    EXPECT_EQ(in[1].piece, 9u);
    EXPECT_FALSE(in[1].fragment);
    EXPECT_EQ(in[0].piece, 7u);
    ASSERT_TRUE(in[0].fragment);
    const Scene& t = *in[0].fragment;

    EXPECT_EQ(in[0].counts.roots, plain.counts.roots);
    EXPECT_EQ(in[0].counts.nodes, plain.counts.nodes);
    EXPECT_EQ(in[0].counts.uses, plain.counts.uses);
    ASSERT_EQ(in[0].counts.outer_uses.size(), 1u);
    EXPECT_EQ(name_text(in[0].counts.outer_uses[0]), "ATOM_GREY");

    ASSERT_EQ(t.groups.size(), s.groups.size());
    for (size_t i = 0; i < s.groups.size(); ++i) {
        expect_same_origin(t.groups[i].origin, s.groups[i].origin);
        EXPECT_EQ(t.groups[i].first_child, s.groups[i].first_child);
        EXPECT_EQ(t.groups[i].child_count, s.groups[i].child_count);
        EXPECT_EQ(t.groups[i].transform, s.groups[i].transform);
        EXPECT_EQ(t.groups[i].transform_kind, s.groups[i].transform_kind);
        EXPECT_EQ(t.groups[i].singular, s.groups[i].singular);
    }
    ASSERT_EQ(t.child_refs.size(), s.child_refs.size());
    for (size_t i = 0; i < s.child_refs.size(); ++i) {
        EXPECT_EQ(t.child_refs[i].kind, s.child_refs[i].kind);
        EXPECT_EQ(t.child_refs[i].index, s.child_refs[i].index);
    }
    ASSERT_EQ(t.translations.size(), s.translations.size());
    for (size_t i = 0; i < s.translations.size(); ++i)
        EXPECT_EQ(t.translations[i], s.translations[i]);
    EXPECT_EQ(t.matrices, s.matrices);  // bit for bit: == on doubles
    ASSERT_EQ(t.shapes.size(), s.shapes.size());
    for (size_t i = 0; i < s.shapes.size(); ++i) {
        expect_same_origin(t.shapes[i].origin, s.shapes[i].origin);
        EXPECT_EQ(t.shapes[i].appearance, s.shapes[i].appearance);  // an outer node stays one
        EXPECT_EQ(t.shapes[i].geometry, s.shapes[i].geometry);
    }
    ASSERT_EQ(t.translated_shapes.size(), s.translated_shapes.size());
    for (size_t i = 0; i < s.translated_shapes.size(); ++i) {
        const sg::TranslatedShape &x = t.translated_shapes[i], &y = s.translated_shapes[i];
        expect_same_origin(x.group_origin(), y.group_origin());
        expect_same_origin(x.shape().origin, y.shape().origin);
        EXPECT_EQ(x.translation, y.translation);
        EXPECT_EQ(x.appearance, y.appearance);  // an outer node stays one
        EXPECT_EQ(x.geometry, y.geometry);
    }
    EXPECT_TRUE(is_outer_node(t.translated_shapes[1].appearance));
    for (size_t i = 0; i < s.geometries.size(); ++i) {
        expect_same_origin(t.geometries[i].origin, s.geometries[i].origin);
        EXPECT_EQ(t.geometries[i].shape.index(), s.geometries[i].shape.index());
        EXPECT_EQ(t.geometries[i].cull_back_faces, s.geometries[i].cull_back_faces);
    }
    EXPECT_EQ(std::get<sg::Sphere>(t.geometries[0].shape).radius, 0.75);
    const auto& cylinder = std::get<sg::Cylinder>(t.geometries[1].shape);
    EXPECT_EQ(cylinder.height, 2.0);
    EXPECT_FALSE(cylinder.top);
    EXPECT_TRUE(cylinder.bottom);
    EXPECT_EQ(std::get<sg::Box>(t.geometries[2].shape).size, Vec3(1, 2, 3));
    EXPECT_EQ(std::get<sg::Cone>(t.geometries[3].shape).bottom_radius, 0.5);
    ASSERT_EQ(t.appearances.size(), s.appearances.size());
    for (size_t i = 0; i < s.appearances.size(); ++i) {
        expect_same_origin(t.appearances[i].origin, s.appearances[i].origin);
        EXPECT_EQ(t.appearances[i].material, s.appearances[i].material);
        EXPECT_EQ(t.appearances[i].texture, s.appearances[i].texture);
    }
    ASSERT_EQ(t.materials.size(), s.materials.size());
    for (size_t i = 0; i < s.materials.size(); ++i) {
        expect_same_origin(t.materials[i].origin, s.materials[i].origin);
        EXPECT_EQ(t.materials[i].diffuse_color, s.materials[i].diffuse_color);
        EXPECT_EQ(t.materials[i].shininess, s.materials[i].shininess);
        EXPECT_EQ(t.materials[i].ambient_intensity, s.materials[i].ambient_intensity);
    }
}

// A molecule's piece of translated atoms holds no rotation matrix: an array of none must travel as
// one (the process that receives it must not copy from or into no storage at all; the sanitizer
// build of CI fails on that).
TEST(FragmentWire, AnEmptyArrayArrivesEmpty) {
    const PlainPiece plain =
        read("Transform { translation 1 2 3 children Shape { geometry Sphere {} } }\n");
    ASSERT_TRUE(plain.fragment.matrices.empty());
    std::vector<WirePiece> out(1);
    out[0].piece = 3;
    out[0].fragment =
        read("Transform { translation 1 2 3 children Shape { geometry Sphere {} } }\n").fragment;
    out[0].counts = plain.counts;
    const std::vector<WirePiece> in = unpack_pieces(pack_pieces(out));
    ASSERT_EQ(in.size(), 1u);
    ASSERT_TRUE(in[0].fragment);
    EXPECT_TRUE(in[0].fragment->matrices.empty());
    EXPECT_EQ(in[0].fragment->geometries.size(), 1u);
}

TEST(FragmentWire, AFragmentWithMoreThanAPlainPieceHoldsGoesAsNotPlain) {
    std::vector<WirePiece> out(1);
    out[0].fragment = read(kPiece).fragment;
    out[0].fragment->lights.emplace_back();  // a plain piece has no light
    EXPECT_FALSE(fits_wire(*out[0].fragment));
    const std::vector<WirePiece> in = unpack_pieces(pack_pieces(out));
    ASSERT_EQ(in.size(), 1u);
    EXPECT_FALSE(in[0].fragment);
}

TEST(FragmentWire, ACutMessageIsRefused) {
    std::vector<WirePiece> out(1);
    out[0].fragment = read(kPiece).fragment;
    const std::vector<uint8_t> message = pack_pieces(out);
    for (size_t cut : {size_t(4), size_t(20), message.size() / 2, message.size() - 1}) {
        const std::vector<uint8_t> part(message.begin(), message.begin() + long(cut));
        EXPECT_THROW(unpack_pieces(part), std::runtime_error) << "cut at " << cut;
    }
}

}  // namespace
}  // namespace vr
