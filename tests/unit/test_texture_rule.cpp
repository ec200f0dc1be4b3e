// How a texture combines with diffuseColor follows the file's version: an RGB texture replaces
// the colour in VRML97 and X3D 3.x and modulates it in X3D 4.0 (17.2.2.4); a grey texture
// modulates in every version.
#include <gtest/gtest.h>

#include "corpus.h"
#include "flatten/flatten.h"
#include "parser/load.h"
#include "render/camera.h"
#include "render/render.h"
#include "scene/build.h"
#include "scene_text.h"

namespace vr {
namespace {

// The centre pixel of a 16x16 render of `text`, read as `path` (its extension picks nothing: the
// header decides the encoding).
Vec3 centre_pixel(const std::string& text, const std::string& path) {
    const testing::FlattenedText f = testing::flatten_scene_text(text, path);
    EXPECT_EQ(f.build_warnings, 0u) << f.messages;
    RenderOptions o;
    o.width = o.height = 16;
    const Image im = testing::render_from_its_camera(f.flat, o);
    const float* p = &im.rgba[4 * (8 * 16 + 8)];
    return Vec3(p[0], p[1], p[2]);
}

// A red box with a one-texel texture, lit head on by a white DirectionalLight and nothing else (no
// headlight, no ambient light): the front face's colour is exactly its diffuse colour.
std::string box_body(const std::string& texture) {
    return R"(
        Viewpoint { position 0 0 5 }
        NavigationInfo { headlight FALSE }
        DirectionalLight { direction 0 0 -1 }
        Shape { appearance Appearance { material Material { diffuseColor 1 0 0 }
                                        texture PixelTexture { image )" +
           texture + R"( } }
                geometry Box { } })";
}

const std::string kRgb = "1 1 3 0x80FF40";  // (128, 255, 64) / 255
const std::string kGrey = "1 1 1 0x80";
const double k128 = 128.0 / 255.0, k64 = 64.0 / 255.0;
// Texels are 8-bit, the image float: the lit colour is exact up to a few ulps of the products.
const double kTol = 1e-6;

void expect_colour(const Vec3& got, const Vec3& want) {
    EXPECT_NEAR(got.x, want.x, kTol);
    EXPECT_NEAR(got.y, want.y, kTol);
    EXPECT_NEAR(got.z, want.z, kTol);
}

TEST(TextureRule, RgbTextureReplacesDiffuseColourInVrml97AndX3d3) {
    expect_colour(centre_pixel("#VRML V2.0 utf8\n" + box_body(kRgb), "t.wrl"),
                  Vec3(k128, 1.0, k64));
    expect_colour(centre_pixel("#X3D V3.3 utf8\nPROFILE Immersive\n" + box_body(kRgb), "t.x3dv"),
                  Vec3(k128, 1.0, k64));
}

TEST(TextureRule, RgbTextureModulatesDiffuseColourInX3d4) {
    // red * (128, 255, 64) / 255 = (128 / 255, 0, 0)
    expect_colour(centre_pixel("#X3D V4.0 utf8\nPROFILE Immersive\n" + box_body(kRgb), "t.x3dv"),
                  Vec3(k128, 0.0, 0.0));
}

TEST(TextureRule, XmlVersionAttributeChoosesTheRule) {
    auto xml = [](const std::string& version) {
        return "<?xml version='1.0' encoding='UTF-8'?>\n<X3D profile='Immersive' version='" +
               version + R"('><Scene>
          <Viewpoint position='0 0 5'/><NavigationInfo headlight='false'/>
          <DirectionalLight direction='0 0 -1'/>
          <Shape><Appearance><Material diffuseColor='1 0 0'/>
            <PixelTexture image='1 1 3 0x80FF40'/></Appearance><Box/></Shape>
        </Scene></X3D>)";
    };
    expect_colour(centre_pixel(xml("3.3"), "t.x3d"), Vec3(k128, 1.0, k64));
    expect_colour(centre_pixel(xml("4.0"), "t.x3d"), Vec3(k128, 0.0, 0.0));
}

TEST(TextureRule, GreyTextureModulatesInEveryVersion) {
    for (const std::string header : {"#VRML V2.0 utf8\n", "#X3D V3.3 utf8\nPROFILE Immersive\n",
                                     "#X3D V4.0 utf8\nPROFILE Immersive\n"})
        expect_colour(centre_pixel(header + box_body(kGrey), "t.x3dv"), Vec3(k128, 0.0, 0.0));
}

TEST(TextureRule, HeaderVersion) {
    EXPECT_EQ(x3d_major_version("#X3D V4.0 utf8\n"), 4);
    EXPECT_EQ(x3d_major_version("\xEF\xBB\xBF#X3D V3.3 utf8\n"), 3);
    EXPECT_EQ(x3d_major_version("#VRML V2.0 utf8\n"), 0);
    // The XML declaration's version is not the X3D version; nor is an element named X3Dsomething.
    EXPECT_EQ(x3d_major_version("<?xml version=\"1.0\"?>\n<!-- <X3Dx version='9'> -->\n"
                                "<X3D profile='Full' version = \"4.1\">"),
              4);
    EXPECT_EQ(x3d_major_version("<?xml version=\"1.0\"?><X3D profile='Full'><Scene/></X3D>"), 0);
}

TEST(TextureRuleCorpus, RealFilesCarryTheirHeadersVersion) {
    VR_CORPUS_FOLDER(corpus, "");
    // The one X3D 4.0 file of the corpus (its DOCTYPE names "X3D 4.0" before the element does),
    // an X3D 3.2 classic file and a VRML97 one: the version that reaches the scene builder.
    const std::pair<const char*, int> files[] = {
        {"x3d/castle-engine-demo-models/svg/cge_logo_fixed_z.x3d", 4},
        {"x3dv/castle-engine-demo-models/texturing_advanced/inlined_pixel_textures.x3dv", 3},
        {"vrml97/castle-engine-demo-models/vrml_2/cones.wrl", 0}};
    for (const auto& [name, major] : files) {
        const LoadedScene loaded = load_scene(corpus / name);
        ASSERT_FALSE(loaded.x3d_major.empty()) << name;
        EXPECT_EQ(loaded.x3d_major[0], major) << name;
    }
}

}  // namespace
}  // namespace vr
