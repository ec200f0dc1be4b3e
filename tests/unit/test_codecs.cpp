// The codecs that replaced OpenImageIO for the common formats: JPEG (libjpeg-turbo) and EXR (the
// OpenEXR module) must return exactly what the OpenImageIO module returns for the same file, EXR
// output must not change from run to run, and damaged files must give an error, never a crash.
#include <gtest/gtest.h>
#include <unistd.h>

#include <climits>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "image/exr.h"
#include "image/image.h"
#include "image/jpeg.h"
#include "image/oiio_module.h"
#include "image/texture_file.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

class CodecsTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("vrmlray_codecs_" + std::to_string(::getpid()) + "_" + info->name());
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

std::vector<char> bytes_of(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}

void write_bytes(const std::string& path, const std::vector<char>& bytes) {
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

std::vector<std::string> corpus_jpegs() {
    std::vector<std::string> out;
    const fs::path root = fs::path(VRMLRAY_CORPUS_DIR) / "vrml97/castle-engine-demo-models";
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(root, ec); !ec && it != fs::end(it);
         it.increment(ec))
        if (it->path().extension() == ".jpg") out.push_back(it->path().string());
    std::sort(out.begin(), out.end());
    return out;
}

// Real textures (the castle demo's 20 JPEGs): the same samples as OpenImageIO, to the bit, so
// that renders of JPEG-textured scenes do not change with the reader.
TEST_F(CodecsTest, CorpusJpegsReadAsOpenImageIOReadsThem) {
    const std::vector<std::string> files = corpus_jpegs();
    if (files.empty()) GTEST_SKIP() << "no corpus under " << VRMLRAY_CORPUS_DIR;
    for (const std::string& file : files) {
        JpegPixels mine;
        std::string error;
        ASSERT_EQ(read_jpeg(file, kMaxImagePixels, mine, error), JpegStatus::kOk) << file << error;
        OiioPixels oiio;
        ASSERT_TRUE(oiio_read_pixels(file, INT_MAX, kMaxImagePixels, oiio, error)) << error;
        EXPECT_EQ(mine.width, oiio.width) << file;
        EXPECT_EQ(mine.height, oiio.height) << file;
        ASSERT_EQ(mine.channels, oiio.channels) << file;
        EXPECT_TRUE(mine.samples == oiio.samples) << file;
    }
}

// No grey JPEG in the corpus: one written by OpenImageIO stays one channel, read identically.
TEST_F(CodecsTest, GreyJpegIsOneChannel) {
    std::vector<uint8_t> grey(37 * 23);
    for (size_t i = 0; i < grey.size(); ++i) grey[i] = uint8_t(i * 7);
    std::string error;
    ASSERT_TRUE(
        oiio_write_pixels(path("grey.jpg"), 37, 23, 1, VR_OIIO_UINT8, grey.data(), false, error))
        << error;
    JpegPixels mine;
    ASSERT_EQ(read_jpeg(path("grey.jpg"), kMaxImagePixels, mine, error), JpegStatus::kOk) << error;
    OiioPixels oiio;
    ASSERT_TRUE(oiio_read_pixels(path("grey.jpg"), INT_MAX, kMaxImagePixels, oiio, error));
    EXPECT_EQ(mine.channels, 1);
    EXPECT_TRUE(mine.samples == oiio.samples);
    ImageData tex;
    ASSERT_TRUE(read_image_file(path("grey.jpg"), tex, error)) << error;
    EXPECT_EQ(tex.channels, 1);
    EXPECT_EQ(tex.width, 37);
}

TEST_F(CodecsTest, JpegSizeLimitIsCheckedFromTheHeader) {
    const std::vector<std::string> files = corpus_jpegs();
    if (files.empty()) GTEST_SKIP() << "no corpus";
    JpegPixels px;
    std::string error;
    ASSERT_EQ(read_jpeg(files[0], 1000, px, error), JpegStatus::kError);
    EXPECT_NE(error.find("too large"), std::string::npos) << error;
    EXPECT_TRUE(px.samples.empty());
}

// EXR through the OpenEXR module: floats out of [0,1] and negative ones survive exactly, the
// OpenImageIO module reads the file to the same values, and a second write gives the same bytes.
TEST_F(CodecsTest, ExrIsExactReadableByOpenImageIOAndDeterministic) {
    Image im(5, 3);
    for (size_t i = 0; i < im.rgba.size(); ++i) im.rgba[i] = float(i) * 0.37f - 2.0f;
    for (const bool alpha : {false, true}) {
        std::string error;
        const WriteOptions options{false, alpha};
        ASSERT_TRUE(write_image(path("a.exr"), im, options, error)) << error;
        ASSERT_TRUE(write_image(path("b.exr"), im, options, error)) << error;
        EXPECT_EQ(bytes_of(path("a.exr")), bytes_of(path("b.exr")));
        Image back;
        ASSERT_TRUE(read_image(path("a.exr"), back, error)) << error;
        EXPECT_EQ(back.file_channels, alpha ? 4 : 3);
        OiioPixels oiio;
        ASSERT_TRUE(oiio_read_pixels(path("a.exr"), INT_MAX, kMaxImagePixels, oiio, error));
        ASSERT_EQ(oiio.channels, alpha ? 4 : 3);
        for (size_t p = 0; p < 15; ++p)
            for (int c = 0; c < oiio.channels; ++c) {
                EXPECT_EQ(back.rgba[p * 4 + size_t(c)], im.rgba[p * 4 + size_t(c)]);
                EXPECT_EQ(oiio.samples[p * size_t(oiio.channels) + size_t(c)],
                          im.rgba[p * 4 + size_t(c)]);
            }
    }
}

// An EXR texture comes bottom row first, like every texture.
TEST_F(CodecsTest, ExrTexturesAreRead) {
    Image im(2, 2);
    for (size_t i = 0; i < im.rgba.size(); ++i) im.rgba[i] = float(i) / 16.0f;
    std::string error;
    ASSERT_TRUE(write_image(path("t.exr"), im, WriteOptions{false, false}, error)) << error;
    ImageData tex;
    ASSERT_TRUE(read_image_file(path("t.exr"), tex, error)) << error;
    ASSERT_EQ(tex.channels, 3);
    EXPECT_EQ(tex.texels[0], im.pixel(0, 1)[0]);
    EXPECT_EQ(tex.texels[3 * 3 + 2], im.pixel(1, 0)[2]);
}

// Cut and damaged files: an error or (for JPEG data damage, which libjpeg repairs with a
// warning, as OpenImageIO does) an image, never a crash or a hang.
TEST_F(CodecsTest, DamagedJpegAndExrNeverCrash) {
    Image im(16, 16);
    for (size_t i = 0; i < im.rgba.size(); ++i) im.rgba[i] = float(i % 17) / 16.0f;
    std::string error;
    ASSERT_TRUE(write_image(path("good.exr"), im, WriteOptions{false, true}, error)) << error;
    std::vector<std::vector<char>> seeds = {bytes_of(path("good.exr"))};
    const std::vector<std::string> jpegs = corpus_jpegs();
    if (!jpegs.empty()) seeds.push_back(bytes_of(jpegs[0]));
    std::mt19937 rng(7);
    for (int i = 0; i < 200; ++i) {
        std::vector<char> bytes = seeds[size_t(i) % seeds.size()];
        if (i % 4 == 0) bytes.resize(4 + rng() % (bytes.size() - 4));  // keep the signature
        for (int f = 0; f < 1 + i % 5; ++f) bytes[4 + rng() % (bytes.size() - 4)] = char(rng());
        write_bytes(path("bad"), bytes);
        Image back;
        if (!read_image(path("bad"), back, error)) {
            EXPECT_NE(error.find(path("bad")), std::string::npos) << error;
        }
    }
    // A file that is only a signature is an error, with the file named.
    write_bytes(path("cut.jpg"), {char(0xFF), char(0xD8), char(0xFF)});
    Image back;
    EXPECT_FALSE(read_image(path("cut.jpg"), back, error));
    EXPECT_NE(error.find("cut.jpg"), std::string::npos) << error;
    write_bytes(path("cut.exr"), {0x76, 0x2f, 0x31, 0x01});
    EXPECT_FALSE(read_image(path("cut.exr"), back, error));
    EXPECT_NE(error.find("cut.exr"), std::string::npos) << error;
}

}  // namespace
}  // namespace vr
