// URLs load like a browser loads them (relative, absolute and file: URLs anywhere the user can
// read; network URLs never fetched), and --sandbox confines every read to one folder for untrusted
// input.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "flatten/flatten.h"
#include "image/image.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/render.h"
#include "scene/build.h"
#include "temp_path.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

std::string errors(const LoadedScene& s) { return s.diagnostics.format(s.sources); }

size_t count_of(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

struct TempDir {
    fs::path path;
    explicit TempDir(const std::string& name) : path(vr::test::temp_path("vrmlray_urls_" + name)) {
        fs::remove_all(path);
        fs::create_directories(path);
        path = fs::canonical(path);
    }
    ~TempDir() { fs::remove_all(path); }
    fs::path write(const std::string& name, const std::string& text) const {
        fs::path p = path / name;
        fs::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << text;
        return p;
    }
};

LoadOptions sandboxed(const fs::path& dir = {}, std::vector<fs::path> extra = {}) {
    LoadOptions o;
    o.sandbox = true;
    o.sandbox_dir = dir;
    o.allowed_roots = std::move(extra);
    return o;
}

const char* kBoxFile = "#VRML V2.0 utf8\nShape { geometry Box {} }\n";

TEST(Urls, RelativeAbsoluteAndFileUrlsReachParentFoldersLikeABrowser) {
    // "../textures/x.jpg" and "../models/part.wrl" are how real exports refer to shared files.
    TempDir dir("parent");
    const fs::path part = dir.write("models/part.wrl", kBoxFile);
    dir.write("lib/protos.wrl", "#VRML V2.0 utf8\nPROTO Ball [] { Sphere { radius 2 } }\n");
    const fs::path main = dir.write(
        "scenes/main.wrl",
        "#VRML V2.0 utf8\nEXTERNPROTO Ball [] \"../lib/protos.wrl\"\nShape { geometry Ball {} }\n"
        "Inline { url \"../models/part.wrl\" }\nInline { url \"" +
            part.string() +
            "\" }\n"
            "Inline { url \"file://" +
            part.string() +
            "\" }\nInline { url \"file:../models/part.wrl\" }\n"
            "Inline { url \"%2e%2e/models/part.wrl\" }\n");
    LoadedScene s = load_scene(main);
    ASSERT_TRUE(s.ok()) << errors(s);
    EXPECT_EQ(s.diagnostics.warning_count(), 0u) << errors(s);
    EXPECT_EQ(s.tree.inline_roots.size(), 5u);
    EXPECT_EQ(s.tree.type_name(s.tree.get_node(s.tree.roots[0], intern("geometry"))), "Sphere");
    EXPECT_TRUE(s.allowed_roots.empty());  // not confined
}

TEST(Urls, NetworkUrlsAreNeverFetchedAndTheNextUrlIsTried) {
    TempDir dir("network");
    dir.write("part.wrl", kBoxFile);
    const fs::path main =
        dir.write("main.wrl",
                  "#VRML V2.0 utf8\n"
                  "Inline { url [ \"http://example.com/a.wrl\" \"https://example.com/b.wrl\" "
                  "\"ftp://example.com/c.wrl\" "
                  "\"urn:example:d\" \"file://otherhost/e.wrl\" \"part.wrl\" ] }\n"
                  "Inline { url [ \"http://example.com/only.wrl\" \"urn:x:y\" ] }\n");
    LoadedScene s = load_scene(main);
    ASSERT_TRUE(s.ok()) << errors(s);
    EXPECT_EQ(s.tree.inline_roots.size(), 1u);  // the first Inline, from part.wrl
    const std::string e = errors(s);
    EXPECT_EQ(s.diagnostics.warning_count(), 1u) << e;  // the second Inline, which has no local URL
    EXPECT_NE(e.find("'http://example.com/only.wrl' is never fetched"), std::string::npos) << e;
    EXPECT_NE(e.find("'urn:x:y' is never fetched"), std::string::npos) << e;
    std::string why;
    EXPECT_TRUE(resolve_url("file://otherhost/e.wrl", main, {}, why).empty());
    EXPECT_NE(why.find("another machine"), std::string::npos) << why;
}

// Every way out of the scene's folder: `..`, absolute paths, file: URLs, percent-encoded dots, a
// symbolic link to a file and one to a folder, a `..` after a subfolder, an EXTERNPROTO.
struct Escapes {
    TempDir dir{"sandbox"};
    fs::path main;
    Escapes() {
        const fs::path secret = dir.write("outside/secret.wrl", kBoxFile);
        dir.write("outside/protos.wrl", "#VRML V2.0 utf8\nPROTO Ball [] { Sphere {} }\n");
        dir.write("scene/inside.wrl", kBoxFile);
        dir.write("scene/sub/keep.txt", "");
        fs::create_symlink(secret, dir.path / "scene/link.wrl");
        fs::create_directory_symlink(dir.path / "outside", dir.path / "scene/linkdir");
        std::string text =
            "#VRML V2.0 utf8\nEXTERNPROTO Ball [] \"../outside/protos.wrl\"\nShape { geometry Ball "
            "{} }\n";
        for (const std::string& url :
             {std::string("../outside/secret.wrl"), secret.string(), "file://" + secret.string(),
              "file:" + secret.string(), std::string("%2e%2e/outside/secret.wrl"),
              std::string("%2E%2E%2Foutside%2Fsecret.wrl"), std::string("link.wrl"),
              std::string("linkdir/secret.wrl"), std::string("sub/../../outside/secret.wrl")})
            text += "Inline { url \"" + url + "\" }\n";
        text += "Inline { url \"inside.wrl\" }\n";
        main = dir.write("scene/main.wrl", text);
    }
};
constexpr size_t kEscapes = 9;

TEST(Urls, SandboxRefusesEveryPathOutOfTheScenesFolder) {
    Escapes t;
    LoadedScene s = load_scene(t.main, sandboxed());
    ASSERT_TRUE(s.ok()) << errors(s);
    const std::string e = errors(s);
    EXPECT_EQ(s.tree.inline_roots.size(), 1u) << e;  // inside.wrl only
    EXPECT_EQ(count_of(e, "lies outside the --sandbox folder " + (t.dir.path / "scene").string()),
              kEscapes + 1)
        << e;
    EXPECT_NE(e.find("EXTERNPROTO Ball not resolved"), std::string::npos) << e;
    EXPECT_NE(e.find("--allow-path DIR"), std::string::npos)
        << e;  // the way out, for a trusted folder

    // The same file without --sandbox: every URL loads.
    LoadedScene open = load_scene(t.main);
    ASSERT_TRUE(open.ok()) << errors(open);
    EXPECT_EQ(open.diagnostics.warning_count(), 0u) << errors(open);
    EXPECT_EQ(open.tree.inline_roots.size(), kEscapes + 1);
}

TEST(Urls, AllowPathAndAnExplicitSandboxFolder) {
    Escapes t;
    // --allow-path adds the outside folder to the sandbox.
    LoadedScene allowed = load_scene(t.main, sandboxed({}, {t.dir.path / "outside"}));
    EXPECT_EQ(allowed.diagnostics.warning_count(), 0u) << errors(allowed);
    EXPECT_EQ(allowed.tree.inline_roots.size(), kEscapes + 1);
    // --sandbox DIR with DIR the common parent: everything is inside.
    LoadedScene parent = load_scene(t.main, sandboxed(t.dir.path));
    EXPECT_EQ(parent.diagnostics.warning_count(), 0u) << errors(parent);
    // --sandbox DIR elsewhere: even the scene's own folder is out.
    fs::create_directories(t.dir.path / "empty");
    LoadedScene elsewhere = load_scene(t.main, sandboxed(t.dir.path / "empty"));
    EXPECT_EQ(elsewhere.tree.inline_roots.size(), 0u) << errors(elsewhere);
}

// Writes a 2x2 PNG of one colour.
void write_png(const fs::path& path, Vec3 colour) {
    Image image(2, 2);
    for (size_t p = 0; p < 4; ++p) {
        image.rgba[4 * p] = float(colour.x);
        image.rgba[4 * p + 1] = float(colour.y);
        image.rgba[4 * p + 2] = float(colour.z);
        image.rgba[4 * p + 3] = 1.0f;
    }
    std::string error;
    ASSERT_TRUE(write_image(path.string(), image, false, error)) << error;
}

FlatScene flatten_file(const fs::path& file, const LoadOptions& options, std::string& messages) {
    LoadedScene loaded = load_scene(file, options);
    Diagnostics diagnostics;
    const Scene scene = build_scene(loaded, diagnostics);
    FlattenOptions fo;
    fo.scene_file = loaded.main_file;
    fo.allowed_roots = loaded.allowed_roots;
    FlattenStats stats;
    FlatScene flat = flatten_scene(scene, fo, diagnostics, stats);
    messages = errors(loaded) + diagnostics.format(loaded.sources);
    return flat;
}

TEST(Urls, TextureAndBackgroundUrlsOutsideTheFolderLoadUnlessSandboxed) {
    TempDir dir("textures");
    fs::create_directories(dir.path / "textures");
    write_png(dir.path / "textures/red.png", Vec3(1.0, 0.0, 0.0));
    const fs::path main = dir.write(
        "scene/main.wrl",
        "#VRML V2.0 utf8\nBackground { frontUrl \"../textures/red.png\" }\n"
        "Shape { appearance Appearance { texture ImageTexture { url \"../textures/red.png\" } } "
        "geometry Box {} }\n");
    std::string messages;
    const FlatScene open = flatten_file(main, {}, messages);
    EXPECT_EQ(open.textures.size(), 2u)
        << messages;  // one per repeat mode: the box's and the panorama's
    EXPECT_EQ(messages.find("warning"), std::string::npos) << messages;
    const FlatScene boxed = flatten_file(main, sandboxed(), messages);
    EXPECT_EQ(boxed.textures.size(), 0u);
    EXPECT_EQ(count_of(messages, "lies outside the --sandbox folder"), 2u) << messages;
}

}  // namespace
}  // namespace vr
