// The wire form of a plain piece's scene fragment (src/app/fragment_wire.h), which processes that
// split a file's reading send each other (docs/mpi.md "Split reading"): what arrives must be the
// fragment that left, array for array and field for field, so that every process splices the
// same scene; a piece that is not plain arrives as such; names arrive as the same texts whatever
// numbers the receiver gave them; parts that do not fit together are refused, not misread.
#include <gtest/gtest.h>

#include <cstring>
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

// What MPI does between the processes: the header, then each part into the receiver's storage.
struct Arrived {
    std::optional<Scene> fragment;
    TextConsumed counts;
};
Arrived travel(const OutgoingPiece& out, NameMap& names) {
    IncomingPiece in(out.header());
    EXPECT_EQ(in.piece(), out.header().piece);
    EXPECT_EQ(in.parts().size(), out.parts().size());
    for (size_t i = 0; i < in.parts().size() && i < out.parts().size(); ++i) {
        EXPECT_EQ(in.parts()[i].size(), out.parts()[i].size()) << "part " << i;
        std::memcpy(in.parts()[i].data(), out.parts()[i].data(),
                    std::min(in.parts()[i].size(), out.parts()[i].size()));
    }
    Arrived a;
    a.fragment = std::move(in).finish(names, a.counts);
    return a;
}

void expect_same_fragment(const Scene& t, const Scene& s) {
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
    ASSERT_EQ(t.geometries.size(), s.geometries.size());
    for (size_t i = 0; i < s.geometries.size(); ++i) {
        expect_same_origin(t.geometries[i].origin, s.geometries[i].origin);
        EXPECT_EQ(t.geometries[i].shape.index(), s.geometries[i].shape.index());
        EXPECT_EQ(t.geometries[i].cull_back_faces, s.geometries[i].cull_back_faces);
        EXPECT_EQ(t.geometries[i].hints, s.geometries[i].hints);
    }
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

TEST(FragmentWire, APlainPieceArrivesAsItLeft) {
    const PlainPiece plain = read(kPiece);
    const Scene& s = plain.fragment;
    ASSERT_TRUE(fits_wire(s));
    ASSERT_EQ(s.matrices.size(), 1u);           // the rotated Transform
    ASSERT_EQ(s.translated_shapes.size(), 2u);  // the first and the last Transform
    ASSERT_EQ(s.geometries.size(), 4u);
    ASSERT_EQ(plain.counts.outer_uses.size(), 1u);

    NameTexts sent;
    NameMap names;
    const OutgoingPiece out(7, &s, plain.counts, sent);
    EXPECT_EQ(out.header().plain, 1u);
    const Arrived in = travel(out, names);
    ASSERT_TRUE(in.fragment);
    // One process: the receiver's numbers are the sender's, and the arrays are taken as they are.
    EXPECT_TRUE(names.identity());
    EXPECT_EQ(in.counts.roots, plain.counts.roots);
    EXPECT_EQ(in.counts.nodes, plain.counts.nodes);
    EXPECT_EQ(in.counts.uses, plain.counts.uses);
    ASSERT_EQ(in.counts.outer_uses.size(), 1u);
    EXPECT_EQ(name_text(in.counts.outer_uses[0]), "ATOM_GREY");
    const Scene& t = *in.fragment;
    expect_same_fragment(t, s);
    EXPECT_TRUE(is_outer_node(t.translated_shapes[1].appearance));
    EXPECT_EQ(std::get<sg::Sphere>(t.geometries[0].shape).radius, 0.75);
    const auto& cylinder = std::get<sg::Cylinder>(t.geometries[1].shape);
    EXPECT_EQ(cylinder.height, 2.0);
    EXPECT_FALSE(cylinder.top);
    EXPECT_TRUE(cylinder.bottom);
    EXPECT_EQ(std::get<sg::Box>(t.geometries[2].shape).size, Vec3(1, 2, 3));
    EXPECT_EQ(std::get<sg::Cone>(t.geometries[3].shape).bottom_radius, 0.5);
}

// The second piece from a sender carries only the names it interned since the first, and the
// receiver's map goes on where it ended.
TEST(FragmentWire, ASendersNamesGoOnce) {
    const PlainPiece a = read(kPiece);
    NameTexts sent;
    NameMap names;
    const OutgoingPiece first(0, &a.fragment, a.counts, sent);
    ASSERT_TRUE(travel(first, names).fragment);
    EXPECT_GT(first.header().new_names, 0u);

    const PlainPiece b = read(
        "Group { children Shape { appearance USE NAME_ONLY_IN_THE_SECOND_PIECE "
        "geometry Sphere {} } }\n");
    const OutgoingPiece second(2, &b.fragment, b.counts, sent);
    EXPECT_EQ(second.header().first_name, first.header().first_name + first.header().new_names);
    EXPECT_EQ(second.header().new_names, 1u);
    const Arrived in = travel(second, names);
    ASSERT_TRUE(in.fragment);
    ASSERT_EQ(in.counts.outer_uses.size(), 1u);
    EXPECT_EQ(name_text(in.counts.outer_uses[0]), "NAME_ONLY_IN_THE_SECOND_PIECE");
    expect_same_fragment(*in.fragment, b.fragment);
}

// A receiver whose numbers differ from the sender's (it interned other names first) renumbers
// every origin: the texts are what must arrive.
TEST(FragmentWire, NamesAreRenumberedWhereTheProcessesDiffer) {
    for (const char* name : {"NAME_1", "NAME_2", "NAME_3", "NAME_4"}) intern(name);  // run alone
    NameTexts sent;
    uint32_t first = 0, count = 0;
    std::vector<uint8_t> texts = sent.next(first, count);
    ASSERT_EQ(first, 0u);
    ASSERT_GT(count, 4u);
    // The sender's names 1 and 2 swapped: as if the receiver had interned them the other way.
    std::vector<uint32_t> at;  // where each name's length is
    for (size_t p = 0; p < texts.size();) {
        at.push_back(uint32_t(p));
        uint32_t length = 0;
        std::memcpy(&length, texts.data() + p, sizeof length);
        p += sizeof length + length;
    }
    ASSERT_EQ(at.size(), count);
    NameMap names;
    std::vector<uint8_t> swapped(texts.begin(), texts.begin() + at[1]);
    swapped.insert(swapped.end(), texts.begin() + at[2], texts.begin() + at[3]);
    swapped.insert(swapped.end(), texts.begin() + at[1], texts.begin() + at[2]);
    swapped.insert(swapped.end(), texts.begin() + at[3], texts.end());
    names.add(swapped, 0, count);
    EXPECT_FALSE(names.identity());
    EXPECT_EQ(names(1), Name(2));
    EXPECT_EQ(names(2), Name(1));
    EXPECT_EQ(names(3), Name(3));
    EXPECT_THROW(names(count), std::runtime_error);
    // A names part that does not follow the last one is refused.
    EXPECT_THROW(names.add(texts, 0, count), std::runtime_error);
}

// The texts of a names part with the entries of names `a` and `b` swapped.
std::vector<uint8_t> swap_names(std::span<const uint8_t> texts, Name a, Name b) {
    std::vector<std::vector<uint8_t>> entries;
    for (size_t p = 0; p < texts.size();) {
        uint32_t length = 0;
        std::memcpy(&length, texts.data() + p, sizeof length);
        entries.emplace_back(texts.begin() + long(p),
                             texts.begin() + long(p + sizeof length + length));
        p += sizeof length + length;
    }
    std::swap(entries.at(a), entries.at(b));
    std::vector<uint8_t> out;
    for (const auto& e : entries) out.insert(out.end(), e.begin(), e.end());
    return out;
}

void swap_type(sg::Origin& o, Name a, Name b) {
    if (o.type == a)
        o.type = b;
    else if (o.type == b)
        o.type = a;
}

// A sender that numbered "Transform" and "Shape" the other way round: its fragment holds its
// numbers, its names part its texts, and the receiver must renumber every origin to its own.
TEST(FragmentWire, RenumberedOriginsArriveAsTheirTexts) {
    const PlainPiece plain = read(kPiece);
    PlainPiece theirs = read(kPiece);
    const Name a = intern("Transform"), b = intern("Shape");
    Scene& s = theirs.fragment;
    for (size_t i = 0; i < s.groups.size(); ++i) swap_type(s.groups[i].origin, a, b);
    for (size_t i = 0; i < s.shapes.size(); ++i) swap_type(s.shapes[i].origin, a, b);
    for (sg::Geometry& g : s.geometries) swap_type(g.origin, a, b);
    for (sg::Appearance& x : s.appearances) swap_type(x.origin, a, b);
    for (sg::Material& x : s.materials) swap_type(x.origin, a, b);

    NameTexts sent;
    const OutgoingPiece out(5, &s, theirs.counts, sent);
    ASSERT_EQ(out.header().first_name, 0u);  // the names part holds every name: a and b too
    IncomingPiece in(out.header());
    ASSERT_EQ(in.parts().size(), out.parts().size());
    for (size_t i = 1; i < in.parts().size(); ++i)
        std::memcpy(in.parts()[i].data(), out.parts()[i].data(), in.parts()[i].size());
    const std::vector<uint8_t> texts = swap_names(out.parts()[0], a, b);
    ASSERT_EQ(texts.size(), in.parts()[0].size());
    std::memcpy(in.parts()[0].data(), texts.data(), texts.size());
    NameMap names;
    TextConsumed counts;
    std::optional<Scene> t = std::move(in).finish(names, counts);
    EXPECT_FALSE(names.identity());
    ASSERT_TRUE(t);
    expect_same_fragment(*t, plain.fragment);
    EXPECT_EQ(t->groups[1].origin.type_text(), "Transform");
}

// A molecule's piece of translated atoms holds no rotation matrix: an array of none must travel as
// none (no part is sent for it, and no storage is copied from or into; the sanitizer build of CI
// fails on a copy of none).
TEST(FragmentWire, AnEmptyArrayArrivesEmpty) {
    const PlainPiece plain =
        read("Transform { translation 1 2 3 children Shape { geometry Sphere {} } }\n");
    ASSERT_TRUE(plain.fragment.matrices.empty());
    NameTexts sent;
    NameMap names;
    const OutgoingPiece out(3, &plain.fragment, plain.counts, sent);
    for (const std::span<const uint8_t> part : out.parts()) EXPECT_FALSE(part.empty());
    const Arrived in = travel(out, names);
    ASSERT_TRUE(in.fragment);
    EXPECT_TRUE(in.fragment->matrices.empty());
    EXPECT_EQ(in.fragment->geometries.size(), 1u);
}

TEST(FragmentWire, AFragmentWithMoreThanAPlainPieceHoldsGoesAsNotPlain) {
    PlainPiece plain = read(kPiece);
    plain.fragment.lights.emplace_back();  // a plain piece has no light
    EXPECT_FALSE(fits_wire(plain.fragment));
    NameTexts sent;
    NameMap names;
    const OutgoingPiece out(9, &plain.fragment, plain.counts, sent);
    EXPECT_EQ(out.header().plain, 0u);
    EXPECT_TRUE(out.parts().empty());
    const OutgoingPiece none(11, nullptr, TextConsumed(), sent);  // its reader gave up
    EXPECT_EQ(none.header().plain, 0u);
    EXPECT_FALSE(travel(out, names).fragment);
    EXPECT_FALSE(travel(none, names).fragment);
}

// A geometry record of a kind no plain piece makes, or a names part cut short, is refused.
TEST(FragmentWire, PartsThatDoNotFitAreRefused) {
    const PlainPiece plain = read(kPiece);
    NameTexts sent;
    const OutgoingPiece out(1, &plain.fragment, plain.counts, sent);
    {
        NameMap names;
        IncomingPiece in(out.header());
        for (size_t i = 0; i < in.parts().size(); ++i)
            std::memcpy(in.parts()[i].data(), out.parts()[i].data(), in.parts()[i].size());
        in.parts()[0][0] ^= 0x40;  // the first name's length: past the end of the part
        TextConsumed counts;
        EXPECT_THROW(std::move(in).finish(names, counts), std::runtime_error);
    }
    {
        NameMap names;
        IncomingPiece in(out.header());
        for (size_t i = 0; i < in.parts().size(); ++i)
            std::memcpy(in.parts()[i].data(), out.parts()[i].data(), in.parts()[i].size());
        // The geometry records are the last part; the kind byte follows origin, hints and flag.
        const std::span<uint8_t> records = in.parts().back();
        records[sizeof(sg::Origin) + sizeof(sg::Index) + 1] = 200;
        TextConsumed counts;
        EXPECT_THROW(std::move(in).finish(names, counts), std::runtime_error);
    }
}

}  // namespace
}  // namespace vr
