// Pieces of a large file built into typed scene fragments while it is read (src/scene/fragments.h,
// issue 16): the scene spliced from them must equal the one built from the whole node tree, field
// by field and index by index, with the same messages in the same order, for real exports and for
// the cases no export has (a warning, a DEF or a UNIT after the pieces, the node limit).
// VRMLRAY_PIECE_BYTES forces pieces far smaller than a real run's 16 MB.
#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "corpus.h"
#include "parser/load.h"
#include "scene/build.h"
#include "scene/fragments.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

LoadedScene load_in_pieces(const fs::path& file, size_t piece, bool consume,
                           LoadLimits limits = {}) {
    setenv("VRMLRAY_PIECE_BYTES", std::to_string(piece).c_str(), 1);
    LoadOptions options;
    options.limits = limits;
    if (consume) options.piece_consumer = std::make_shared<SceneFragments>();
    LoadedScene scene = load_scene(file, options);
    unsetenv("VRMLRAY_PIECE_BYTES");
    return scene;
}

std::string loc(const sg::Origin& o) {
    return std::string(o.type_text()) + "@" + std::to_string(o.loc.get().file) + ":" +
           std::to_string(o.loc.get().offset) + "/" + std::string(o.def_text());
}

// "" when the two scenes are equal in every array the flattening reads; else the first difference.
std::string scene_difference(const Scene& a, const Scene& b) {
    const auto sizes = [](const Scene& s) {
        return std::array<size_t, 15>{
            s.groups.size(),      s.child_refs.size(),     s.translations.size(),
            s.matrices.size(),    s.shapes.size(),         s.geometries.size(),
            s.appearances.size(), s.materials.size(),      s.textures.size(),
            s.lights.size(),      s.viewpoints.size(),     s.backgrounds.size(),
            s.hints.size(),       s.billboard_axes.size(), s.translated_shapes.size()};
    };
    static const char* const kArrays[15] = {"group",   "child_ref", "translation",     "matrix",
                                            "shape",   "geometry",  "appearance",      "material",
                                            "texture", "light",     "viewpoint",       "background",
                                            "hints",   "billboard", "translated shape"};
    const auto na = sizes(a), nb = sizes(b);
    for (size_t k = 0; k < na.size(); ++k)
        if (na[k] != nb[k])
            return std::string(kArrays[k]) + " count " + std::to_string(na[k]) + " vs " +
                   std::to_string(nb[k]);
    for (size_t i = 0; i < a.groups.size(); ++i) {
        const sg::Group &x = a.groups[i], &y = b.groups[i];
        if (loc(x.origin) != loc(y.origin) || x.first_child != y.first_child ||
            x.child_count != y.child_count || x.transform != y.transform ||
            x.transform_kind != y.transform_kind || x.singular != y.singular ||
            x.inline_content != y.inline_content)
            return "group " + std::to_string(i) + " (" + loc(x.origin) + ")";
    }
    for (size_t i = 0; i < a.child_refs.size(); ++i)
        if (a.child_refs[i].kind != b.child_refs[i].kind ||
            a.child_refs[i].index != b.child_refs[i].index)
            return "child_ref " + std::to_string(i);
    for (size_t i = 0; i < a.translations.size(); ++i)
        if (a.translations[i] != b.translations[i]) return "translation " + std::to_string(i);
    for (size_t i = 0; i < a.matrices.size(); ++i)
        if (a.matrices[i] != b.matrices[i]) return "matrix " + std::to_string(i);
    for (size_t i = 0; i < a.shapes.size(); ++i) {
        const sg::Shape &x = a.shapes[i], &y = b.shapes[i];
        if (loc(x.origin) != loc(y.origin) || x.appearance != y.appearance ||
            x.geometry != y.geometry || x.hints != y.hints)
            return "shape " + std::to_string(i);
    }
    for (size_t i = 0; i < a.translated_shapes.size(); ++i) {
        const sg::TranslatedShape &x = a.translated_shapes[i], &y = b.translated_shapes[i];
        if (loc(x.group_origin()) != loc(y.group_origin()) ||
            loc(x.shape().origin) != loc(y.shape().origin) || x.translation != y.translation ||
            x.appearance != y.appearance || x.geometry != y.geometry)
            return "translated shape " + std::to_string(i) + " (" + loc(x.group_origin()) + ")";
    }
    for (size_t i = 0; i < a.geometries.size(); ++i) {
        const sg::Geometry &x = a.geometries[i], &y = b.geometries[i];
        bool same = loc(x.origin) == loc(y.origin) && x.hints == y.hints &&
                    x.shape.index() == y.shape.index();
        if (same && std::holds_alternative<sg::Sphere>(x.shape))
            same = std::get<sg::Sphere>(x.shape).radius == std::get<sg::Sphere>(y.shape).radius;
        if (same && std::holds_alternative<sg::Box>(x.shape))
            same = std::get<sg::Box>(x.shape).size == std::get<sg::Box>(y.shape).size;
        if (same && std::holds_alternative<sg::Cylinder>(x.shape)) {
            const auto &p = std::get<sg::Cylinder>(x.shape), &q = std::get<sg::Cylinder>(y.shape);
            same = p.radius == q.radius && p.height == q.height && p.side == q.side &&
                   p.top == q.top && p.bottom == q.bottom;
        }
        if (same && std::holds_alternative<sg::Cone>(x.shape)) {
            const auto &p = std::get<sg::Cone>(x.shape), &q = std::get<sg::Cone>(y.shape);
            same = p.bottom_radius == q.bottom_radius && p.height == q.height && p.side == q.side &&
                   p.bottom == q.bottom;
        }
        if (!same) return "geometry " + std::to_string(i) + " (" + loc(x.origin) + ")";
    }
    for (size_t i = 0; i < a.appearances.size(); ++i) {
        const sg::Appearance &x = a.appearances[i], &y = b.appearances[i];
        if (loc(x.origin) != loc(y.origin) || x.material != y.material || x.texture != y.texture ||
            x.has_texture_transform != y.has_texture_transform ||
            x.texture_modulates != y.texture_modulates)
            return "appearance " + std::to_string(i);
    }
    for (size_t i = 0; i < a.materials.size(); ++i) {
        const sg::Material &x = a.materials[i], &y = b.materials[i];
        if (loc(x.origin) != loc(y.origin) || x.model != y.model ||
            x.diffuse_color != y.diffuse_color || x.specular_color != y.specular_color ||
            x.emissive_color != y.emissive_color || x.ambient_intensity != y.ambient_intensity ||
            x.shininess != y.shininess || x.transparency != y.transparency ||
            x.metallic != y.metallic || x.roughness != y.roughness || x.hints != y.hints)
            return "material " + std::to_string(i);
    }
    return "";
}

// Reads `file` by one thread and in `piece`-byte pieces built as they are read; "" when the two
// give the same scene and the same messages (reading and building), and the same exit.
// `from_text`: how many of the consumed pieces were built from their tokens (plain_piece.h).
std::string difference(const fs::path& file, size_t piece, size_t* consumed = nullptr,
                       LoadLimits limits = {}, size_t* from_text = nullptr) {
    LoadedScene one = load_in_pieces(file, 0, false, limits);
    LoadedScene many = load_in_pieces(file, piece, true, limits);
    if (consumed) *consumed = many.consumed_pieces.size();
    if (from_text) {
        const auto* f = dynamic_cast<const SceneFragments*>(many.piece_consumer.get());
        *from_text = f ? f->text_pieces() : 0;
    }
    const std::string r1 = one.diagnostics.format(one.sources);
    const std::string r2 = many.diagnostics.format(many.sources);
    if (r1 != r2) return "reading messages differ:\n" + r1 + "---\n" + r2;
    if (one.ok() != many.ok()) return "one read failed";
    if (one.stats.def_count != many.stats.def_count || one.stats.use_count != many.stats.use_count)
        return "DEF or USE counts differ: " + std::to_string(one.stats.use_count) + " vs " +
               std::to_string(many.stats.use_count) + " USEs";
    if (!one.ok()) return "";
    Diagnostics d1, d2;
    const Scene a = build_scene_releasing_tree(one, d1);
    const Scene b = build_scene_releasing_tree(many, d2);
    if (many.piece_consumer) return "the fragments were not released";
    const std::string m1 = d1.format(one.sources), m2 = d2.format(many.sources);
    if (m1 != m2) return "build messages differ:\n" + m1 + "---\n" + m2;
    return scene_difference(a, b);
}

TEST(SceneFragments, EveryCorpusFileBuildsAsFromTheWholeTree) {
    VR_CORPUS_FOLDER(corpus, "");
    size_t files = 0, built = 0;
    for (const fs::path& file : test::classic_files(corpus)) {
        size_t consumed = 0;
        EXPECT_EQ(difference(file, test::small_piece_bytes(file), &consumed), "") << file;
        ++files;
        built += consumed > 0;
    }
    EXPECT_GT(files, 100u);
    // The molecule exports (PyMOL spheres and sticks, RasMol, Jmol's spheres) and many plain
    // scenes are built in pieces; a bound of 10 files says the path is taken, not skipped.
    EXPECT_GT(built, 10u) << "pieces were built in " << built << " of " << files << " files";
}

// The same for X3D XML (parser/x3d_xml_pieces.cpp): every XML file of the corpus, and an XML
// molecule as `vrmlray convert` writes one, whose pieces are built.
TEST(SceneFragments, EveryXmlCorpusFileBuildsAsFromTheWholeTree) {
    VR_CORPUS_FOLDER(corpus, "");
    size_t files = 0;
    for (const fs::path& file : test::xml_files(corpus)) {
        for (size_t piece : {size_t(512), size_t(4096)})
            EXPECT_EQ(difference(file, piece), "") << file << " in pieces of " << piece;
        ++files;
    }
    EXPECT_GT(files, 20u);
}

// An XML file of `text` builds as from the whole tree in pieces of 256 and 4096 bytes, and at
// least half of its pieces are consumed as fragments.
void expect_xml_pieces_built(const std::string& text, const char* name) {
    const fs::path path = test::temp_path(name).string() + ".x3d";
    std::ofstream(path) << text;
    for (size_t piece : {256, 4096}) {
        size_t consumed = 0;
        EXPECT_EQ(difference(path, piece, &consumed), "") << piece;
        EXPECT_GT(consumed, text.size() / piece / 2) << piece;
    }
    fs::remove(path);
}

TEST(SceneFragments, XmlMoleculePiecesAreBuilt) {
    std::string text =
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<X3D profile='Full' version='3.3'>\n  "
        "<Scene>\n    <Viewpoint position='0 0 60'/>\n";
    for (int i = 0; i < 1500; ++i)
        text += "    <Transform translation='" + std::to_string(i % 13) + " " +
                std::to_string(i % 7) + " " + std::to_string(i % 5) +
                "'>\n      <Shape>\n        <Appearance>\n          <Material diffuseColor='0." +
                std::to_string(i % 9) +
                " 0.5 0.5'/>\n        </Appearance>\n        <Sphere "
                "radius='0." +
                std::to_string(1 + i % 8) + "'/>\n      </Shape>\n    </Transform>\n";
    text += "  </Scene>\n</X3D>\n";
    expect_xml_pieces_built(text, "vrmlray_fragments_xml");
}

TEST(SceneFragments, XmlPiecesThatUseAnAppearanceDefinedBeforeThemAreBuilt) {
    std::string text =
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<X3D profile='Full' version='3.3'>\n  "
        "<Scene>\n";
    for (int c = 0; c < 4; ++c)
        text += "    <Shape>\n      <Appearance DEF='M" + std::to_string(c) +
                "'>\n        <Material diffuseColor='0." + std::to_string(c + 1) +
                " 0.5 0.5'/>\n      </Appearance>\n      <Sphere/>\n    </Shape>\n";
    for (int i = 0; i < 600; ++i)
        text += "    <Transform translation='" + std::to_string(i) +
                " 0 0'>\n      <Shape>\n        <Appearance USE='M" + std::to_string(i % 4) +
                "'/>\n        <Sphere radius='0." + std::to_string(1 + i % 9) +
                "'/>\n      </Shape>\n    </Transform>\n";
    text += "  </Scene>\n</X3D>\n";
    expect_xml_pieces_built(text, "vrmlray_fragments_xml_use");
}

TEST(SceneFragments, RealMoleculeExportsAreBuiltInPieces) {
    VR_CORPUS_FOLDER(molecular, "molecular");
    for (const char* name :
         {"pymol/il2_spheres.wrl", "pymol/c551_ballstick.wrl", "pymol/pept_sticks.wrl"}) {
        const fs::path file = molecular / name;
        size_t consumed = 0;
        size_t from_text = 0;
        EXPECT_EQ(difference(file, 4096, &consumed, {}, &from_text), "") << name;
        // Every 4 KB piece of these files is atoms and bonds: nearly all are built, and from
        // their tokens (plain_piece.h).
        EXPECT_GT(consumed, fs::file_size(file) / 4096 / 2) << name;
        EXPECT_GT(from_text, consumed * 9 / 10) << name << ": " << consumed << " pieces built";
    }
}

struct TempFile {  // a name of this process's own: CTest runs the tests in parallel processes
    fs::path path;
    explicit TempFile(const std::string& text, const char* extension = ".wrl")
        : path(test::temp_path("vrmlray_fragments").string() + extension) {
        std::ofstream(path) << text;
    }
    ~TempFile() { fs::remove(path); }
};

// PyMOL-style atoms with radii, colours, shapes and transforms that vary, so that a renumbering
// or a merge gone wrong shows.
std::string atoms(int n, int seed) {
    std::string s;
    for (int i = 0; i < n; ++i) {
        const int k = i + seed;
        const char* geometry[] = {"Sphere { radius 0.5 }", "Box { size 1 2 3 }",
                                  "Cylinder { radius 0.2 height 2 }", "Cone { }"};
        s += "Transform { translation " + std::to_string(k % 7) + " " + std::to_string(k % 5) +
             " 1" + (k % 11 == 0 ? " rotation 0 1 0 0.5" : "") +
             " children [ Shape { appearance Appearance { material Material { diffuseColor 0." +
             std::to_string(k % 4) + " 0.5 1 } } geometry " +
             (k % 3 ? "Sphere { radius " + std::to_string(1 + k % 6) + " }"
                    : std::string(geometry[k % 4])) +
             " } Group { children Shape { geometry Sphere { radius 0.25 } } } ] }\n";
    }
    return s;
}

// Atoms that use every field the scene build reads of the plain pattern's nodes (plain_piece.h),
// given, left to its default or dropped, in the spellings exporters write.
std::string plain_atoms(int n, int seed) {
    std::string s;
    for (int i = 0; i < n; ++i) {
        const int k = i + seed;
        const std::string a = std::to_string(k % 7), b = std::to_string(k % 5);
        switch (k % 8) {
            case 0:  // PyMOL's atom
                s += "Transform {\n translation " + a + ".25 -" + b +
                     ".5 1e-1\n children Shape {\n"
                     "  geometry Sphere { radius 1.55 }\n  appearance Appearance {\n   material "
                     "Material { diffuseColor 0.2000 1.0000 0." +
                     a +
                     "\n specularColor 0.8 0.8 "
                     "0.8 shininess 0.8 }\n  }\n }\n}\n";
                break;
            case 1:  // PyMOL's bond: a rotation and a cylinder
                s += "Transform { translation " + a + " " + b +
                     " 2 rotation 0.499724 0.000000 "
                     "0.866185 0." +
                     b +
                     "54346 children [ Shape { geometry Cylinder { radius "
                     "0.25 height 0.7" +
                     a +
                     " } appearance Appearance { material Material { "
                     "diffuseColor 0.2 0.2 1 } } } ] }\n";
                break;
            case 2:  // every Transform field, the bounding box read and dropped, a comment
                s += "Transform { center 1 " + a + " 0 scale 2 1 0." + b +
                     "1 scaleOrientation 1 0 "
                     "0 0.3 rotation 0 0 1 -1.5 translation +.5 -0 " +
                     b +
                     " bboxCenter 0 0 0 "
                     "bboxSize 4 4 4 # a comment\n children [ Shape { geometry Box { size 1 2 " +
                     a + ".5 } } ] }\n";
                break;
            case 3:  // every Material field, commas as white space; a default Sphere
                s += "Shape { appearance Appearance { material Material { ambientIntensity 0." + a +
                     ", diffuseColor 1, 0, 0, emissiveColor 0 0." + b +
                     " 0 shininess 1 "
                     "specularColor 0.5 0.5 0.5 transparency 0.2" +
                     a + " } } geometry Sphere { } }\n";
                break;
            case 4:  // nested groups, an empty list, NULL appearance and material
                s +=
                    "Group { children [ Transform { translation " + a +
                    " 0 0 children [ ] } Group "
                    "{ children Shape { appearance NULL geometry Cone { bottomRadius 0." +
                    b +
                    "5 height 2 bottom FALSE } } } Shape { appearance Appearance { material NULL } "
                    "geometry Cylinder { side FALSE top FALSE bottom TRUE } } ] }\n";
                break;
            case 5:  // a Shape without geometry draws nothing, its appearance is still built
                s += "Transform { translation 0 " + a +
                     " 0 children [ Shape { appearance Appearance "
                     "{ material Material { diffuseColor 0 1 0." +
                     b +
                     " } } } Shape { geometry "
                     "Sphere { radius 0." +
                     a + "5 } } ] }\n";
                break;
            case 6:  // identity and pure-translation transforms, spelled out
                s += "Transform { rotation 0 1 0 0 scale 1 1 1 translation " + b + " " + a +
                     " 3 children Shape { geometry Sphere { radius 2." + b + " } } }\n";
                break;
            default:  // a top-level Shape, a Cone with its defaults
                s += "Shape { geometry Cone { } appearance Appearance { } }\n";
                break;
        }
    }
    return s;
}

TEST(SceneFragments, PlainPiecesAreBuiltFromTheirTokens) {
    // S3's pattern too: each piece USEs Appearances DEF'd among the first atoms.
    std::string uses;
    for (int c = 0; c < 3; ++c)
        uses += "Shape { appearance DEF M" + std::to_string(c) +
                " Appearance { material Material "
                "{ diffuseColor 0." +
                std::to_string(c + 1) + " 0.5 0.5 } } geometry Sphere { } }\n";
    for (int i = 0; i < 300; ++i)
        uses += "Transform { translation " + std::to_string(i) +
                " 0 0 children Shape { "
                "appearance USE M" +
                std::to_string(i % 3) + " geometry Sphere { radius 0." + std::to_string(1 + i % 9) +
                " } } }\n";
    const std::pair<std::string, const char*> cases[] = {
        {"#VRML V2.0 utf8\n" + plain_atoms(400, 0), ".wrl"},
        {"#VRML V2.0 utf8\n" + uses, ".wrl"},
        // X3D: a Shape that is not visible, fields VRML97 lacks read and dropped
        {"#X3D V3.3 utf8\nPROFILE Interchange\n" + plain_atoms(200, 3) +
             "Transform { visible FALSE bboxDisplay TRUE children Shape { visible FALSE "
             "castShadow FALSE geometry Box { } } }\n" +
             plain_atoms(200, 5),
         ".x3dv"},
    };
    int n = 0;
    for (const auto& [text, extension] : cases) {
        TempFile file(text, extension);
        for (size_t piece : {300, 700, 4096}) {
            size_t consumed = 0, from_text = 0;
            EXPECT_EQ(difference(file.path, piece, &consumed, {}, &from_text), "")
                << "case " << n << ", pieces of " << piece << " bytes";
            // Every piece but the first, which the main reader reads itself, is plain.
            EXPECT_GT(consumed, text.size() / piece / 2) << "case " << n << ", " << piece;
            EXPECT_EQ(from_text, consumed) << "case " << n << ", pieces of " << piece;
        }
        ++n;
    }
}

TEST(SceneFragments, PiecesThatAreNotPlainAreReadIntoATree) {
    // What the tree's reading or build would warn about, or what the plain pattern lacks: the
    // piece holding it is read into a tree, with the same messages in the same places.
    const std::string odd[] = {
        "Transform { rotation 0 2 0 1 children Shape { geometry Box { } } }\n",  // axis warned
        "Transform { translation 1 0 0 translation 2 0 0 }\n",                   // given twice
        "Shape { geometry Cylinder { side true } }\n",                           // lower case
        "Shape { geometry Material { } }\n",                                     // wrong type
        "Shape { appearance Appearance { material Material { } material NULL } }\n",
        "Transform { children [ NULL Shape { geometry Box { } } ] }\n",  // NULL among children
        "Shape { geometry Sphere { radius 0 } }\n",                      // zero radius
        "Transform { scale 1 0 1 children Shape { geometry Sphere { } } }\n",  // singular
        "Transform { children Shape { geometry DEF S Sphere { } } }\nShape { geometry USE S }\n",
        "Shape { appearance Appearance { texture ImageTexture { url \"t.png\" } } }\n",
        "Group { children Shape { geometry Sphere { radius 1e999 } } }\n",  // not finite
    };
    int n = 0;
    for (const std::string& line : odd) {
        TempFile file("#VRML V2.0 utf8\n" + plain_atoms(120, n) + line + plain_atoms(120, n + 1));
        for (size_t piece : {300, 4096}) {
            size_t consumed = 0, from_text = 0;
            EXPECT_EQ(difference(file.path, piece, &consumed, {}, &from_text), "")
                << "case " << n << ", pieces of " << piece << " bytes";
            EXPECT_GT(from_text, 0u) << "case " << n << ", pieces of " << piece;
        }
        ++n;
    }
}

TEST(SceneFragments, PlainPiecesKeepTheReadersLimits) {
    // Nesting deeper than --max-depth allows, and more children in one list than a field may
    // hold: the read fails with the same message at the same place.
    std::string deep = "Shape { geometry Box { } }";
    for (int i = 0; i < 8; ++i) deep = "Transform { children [ " + deep + " ] }";
    const std::string many = "Group { children [ Shape { } Shape { } Shape { } ] }\n";
    LoadLimits shallow, narrow;
    shallow.max_nesting_depth = 6;  // the Box is 9 deep
    narrow.max_mf_values = 2;
    std::string spheres;  // no list of more than one node
    for (int i = 0; i < 200; ++i)
        spheres += "Transform { translation " + std::to_string(i) +
                   " 0 0 children [ Shape { geometry Sphere { } } ] }\n";
    const std::pair<std::string, LoadLimits> cases[] = {
        {spheres + deep + "\n" + spheres, shallow},
        {spheres + many + spheres, narrow},
    };
    int n = 0;
    for (const auto& [text, limits] : cases) {
        TempFile file("#VRML V2.0 utf8\n" + text);
        EXPECT_FALSE(load_in_pieces(file.path, 300, true, limits).ok()) << "case " << n;
        for (size_t piece : {300, 4096}) {
            size_t consumed = 0, from_text = 0;
            EXPECT_EQ(difference(file.path, piece, &consumed, limits, &from_text), "")
                << "case " << n << ", pieces of " << piece << " bytes";
            EXPECT_GT(from_text, 0u) << "case " << n << ", pieces of " << piece;
        }
        ++n;
    }
}

TEST(SceneFragments, CutsThatStayInTheTreeBuildAsFromTheWholeTree) {
    const std::string header = "#VRML V2.0 utf8\n";
    const std::string cases[] = {
        // plain atoms: every piece is built
        header + atoms(400, 0),
        // a piece with a build warning (a bad radius, a singular scale) keeps its nodes, so
        // the warning comes in its order among the others
        header + atoms(150, 1) + "Shape { geometry Sphere { radius -1 } }\n" + atoms(100, 2) +
            "Transform { scale 0 1 1 children Shape { geometry Box { } } }\n" + atoms(100, 3) +
            "Shape { geometry Sphere { radius -2 } }\n",
        // DEF in one piece, USE in a later one; lights and a viewpoint between atoms
        header + atoms(100, 4) + "DEF M Material { diffuseColor 1 0 0 }\n" + atoms(100, 5) +
            "Shape { appearance Appearance { material USE M } geometry Box { } }\n" +
            "PointLight { location 1 2 3 }\nViewpoint { position 0 0 9 }\n" + atoms(100, 6),
        // metadata hints and a texture inside atoms' pieces
        header + atoms(100, 7) +
            "Shape { appearance Appearance { texture ImageTexture { url \"x.png\" } } geometry "
            "Box { } }\n" +
            "Shape { geometry Sphere { radius 2 metadata MetadataSet { name \"vrmlray\" value [ "
            "MetadataString { name \"sphere\" value \"gas\" } ] } } }\n" +
            atoms(100, 8),
        // unknown and unrendered node types among the atoms
        header + atoms(100, 9) + "Unknown { x 1 }\nWorldInfo { }\nPointSet { }\n" + atoms(100, 10),
    };
    int n = 0;
    for (const std::string& text : cases) {
        TempFile file(text);
        for (size_t piece : {64, 700, 4096}) {
            size_t consumed = 0;
            EXPECT_EQ(difference(file.path, piece, &consumed), "")
                << "case " << n << ", pieces of " << piece << " bytes";
            if (n == 0) {
                EXPECT_GT(consumed, 0u);
            }
        }
        ++n;
    }
}

TEST(SceneFragments, PiecesThatUseAnAppearanceDefinedBeforeThemAreBuilt) {
    // The peer harness's S3 (bench/peers.sh) DEFs an Appearance per colour among its first atoms
    // and USEs it in every later one: each piece USEs what a DEF before it names.
    std::string text = "#VRML V2.0 utf8\n";
    for (int c = 0; c < 4; ++c)
        text += "Transform { children Shape { appearance DEF M" + std::to_string(c) +
                " Appearance { material Material { diffuseColor 0." + std::to_string(c + 1) +
                " 0.5 0.5 } } geometry Sphere { radius 1 } } }\n";
    for (int i = 0; i < 600; ++i)
        text += "Transform { translation " + std::to_string(i) + " 0 0 children Shape { " +
                "appearance USE M" + std::to_string(i % 4) + " geometry Sphere { radius 0." +
                std::to_string(1 + i % 9) + " } } }\n";
    TempFile file(text);
    for (size_t piece : {256, 4096}) {
        size_t consumed = 0;
        EXPECT_EQ(difference(file.path, piece, &consumed), "") << piece;
        EXPECT_GT(consumed, text.size() / piece / 2) << piece;
    }
}

TEST(SceneFragments, OuterUsesThatAreNoAppearanceBuildAsFromTheWholeTree) {
    const std::string header = "#VRML V2.0 utf8\n";
    const std::string cases[] = {
        // a Material USEd as an appearance: the builder's warning, in its place
        header +
            "DEF A Material { diffuseColor 1 0 0 }\nShape { appearance Appearance { "
            "material USE A } geometry Box { } }\n" +
            atoms(200, 20) + "Shape { appearance USE A geometry Box { } }\n" + atoms(200, 21),
        // a skipped node's DEF USEd as an appearance; a geometry and a whole group USEd
        header +
            "DEF U Unknown { }\nDEF G Sphere { radius 3 }\nDEF T Transform { children "
            "Shape { geometry Box { } } }\n" +
            atoms(150, 22) + "Shape { appearance USE U geometry USE G }\nUSE T\n" +
            "Group { children USE T }\n" + atoms(150, 23),
        // an Appearance whose material has hints (never merged with another): used again,
        // not built again
        header +
            "Shape { appearance DEF N Appearance { material Material { metadata MetadataSet { "
            "name \"vrmlray\" value [ MetadataFloat { name \"reflectivity\" value 0.5 } ] } } } "
            "geometry Box { } }\n" +
            atoms(150, 24) + "Shape { appearance USE N geometry Sphere { } }\n" + atoms(150, 25),
    };
    int n = 0;
    for (const std::string& text : cases) {
        TempFile file(text);
        for (size_t piece : {64, 700, 4096})
            EXPECT_EQ(difference(file.path, piece), "")
                << "case " << n << ", pieces of " << piece << " bytes";
        ++n;
    }
}

TEST(SceneFragments, AUnitStatementAfterBuiltPiecesReadsTheFileAgain) {
    // X3D UNIT angle converts every rotation of the file, those before it too: the pieces built
    // before it would lack that, so the file is read again without building pieces.
    const std::string text = "#X3D V3.3 utf8\nPROFILE Interchange\n" + atoms(300, 11) +
                             "UNIT angle degree 0.017453292519943295\n" + atoms(50, 12);
    TempFile file(text, ".x3dv");
    LoadedScene many = load_in_pieces(file.path, 1024, true);
    EXPECT_TRUE(many.consumed_pieces.empty());
    EXPECT_EQ(difference(file.path, 1024), "");
}

TEST(SceneFragments, TheNodeLimitStopsAtTheSameNode) {
    TempFile file("#VRML V2.0 utf8\n" + atoms(400, 13));
    LoadLimits limits;
    limits.max_nodes = 1500;  // reached in the middle of the file, well after the first piece
    const std::string d = difference(file.path, 2048, nullptr, limits);
    EXPECT_EQ(d, "");
    LoadedScene many = load_in_pieces(file.path, 2048, true, limits);
    EXPECT_FALSE(many.ok());
    EXPECT_NE(many.diagnostics.format(many.sources).find("more than 1500 nodes (limit)"),
              std::string::npos);
}

TEST(SceneFragments, AnAnimatedFilesSecondBuildStillHasTheFragments) {
    // Frames of an animated scene build from the loaded file again (build_scene, the tree kept):
    // the fragments must still be there, unchanged.
    TempFile file("#VRML V2.0 utf8\n" + atoms(300, 14) +
                  "DEF T TimeSensor { loop TRUE }\nDEF P PositionInterpolator { key [0 1] "
                  "keyValue [0 0 0 1 1 1] }\nDEF X Transform { children Shape { geometry Box "
                  "{ } } }\nROUTE T.fraction_changed TO P.set_fraction\nROUTE P.value_changed "
                  "TO X.set_translation\n");
    LoadedScene many = load_in_pieces(file.path, 1024, true);
    ASSERT_TRUE(many.ok());
    ASSERT_FALSE(many.consumed_pieces.empty());
    Diagnostics d1, d2;
    const Scene first = build_scene(many, d1);
    const Scene second = build_scene(many, d2);
    EXPECT_EQ(scene_difference(first, second), "");
    LoadedScene one = load_in_pieces(file.path, 0, false);
    Diagnostics d3;
    EXPECT_EQ(scene_difference(build_scene(one, d3), second), "");
}

TEST(ChunkedArray, AdoptedChunksKeepTheirPlacesAndLaterElementsGoToANewChunk) {
    ChunkedArray<int> c;
    c.reserve(4);
    c.push_back(0);
    c.resize(3);  // a block of 2 after element 0
    c[1] = 1, c[2] = 2;
    c.adopt({3, 4, 5});
    c.adopt({});           // nothing
    c.emplace_back() = 6;  // not into the adopted chunk: that would move it
    c.resize(9);           // a block of 2, in one chunk: a span of it is contiguous
    c[7] = 7, c[8] = 8;
    c.adopt({9});
    ASSERT_EQ(c.size(), 10u);
    for (int i = 0; i < 10; ++i) EXPECT_EQ(c[size_t(i)], i) << i;
    EXPECT_EQ(c.span(7, 2)[1], 8);
    EXPECT_EQ(&c.span(7, 2)[1], &c[8]);
    int expected = 0;
    for (int v : c) EXPECT_EQ(v, expected++);
    EXPECT_EQ(expected, 10);
    const std::vector<int> all = std::move(c).take_all();
    EXPECT_EQ(all, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
    EXPECT_TRUE(c.empty());
}

}  // namespace
}  // namespace vr
