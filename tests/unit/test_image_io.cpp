// write_image / read_image: what each kind of format stores, and the errors.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "image/image.h"
#include "image/oiio_module.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

class ImageIoTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("vrmlray_image_" + std::to_string(::getpid()) + "_" + info->name());
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    // Writes then reads back; fails the test on any error.
    Image round_trip(const Image& image, const std::string& name, bool srgb = false,
                     bool alpha = false) {
        std::string error;
        EXPECT_TRUE(write_image(path(name), image, WriteOptions{srgb, alpha}, error)) << error;
        Image back;
        EXPECT_TRUE(read_image(path(name), back, error)) << error;
        EXPECT_EQ(back.width, image.width);
        EXPECT_EQ(back.height, image.height);
        return back;
    }

    fs::path dir_;
};

// A 4x3 image whose samples run through [lo, hi] with distinct values.
Image ramp_image(float lo, float hi) {
    Image im(4, 3);
    const size_t n = im.rgba.size();
    for (size_t i = 0; i < n; ++i) im.rgba[i] = lo + (hi - lo) * float(i) / float(n - 1);
    return im;
}

// The 8-bit code of v as a float, computed in double as the writer does (0.9f is just below
// 229.5 / 255).
float code8(float v) {
    return float(std::floor(std::clamp(double(v), 0.0, 1.0) * 255.0 + 0.5)) / 255.0f;
}

TEST_F(ImageIoTest, PngStoresExactEightBitCodes) {
    Image im(16, 16);
    for (int i = 0; i < 256; ++i) {
        float* p = im.pixel(i % 16, i / 16);
        p[0] = float(i) / 255.0f;
        p[1] = float(255 - i) / 255.0f;
        p[2] = float((i * 7) % 256) / 255.0f;
        p[3] = float((i * 13) % 256) / 255.0f;  // no alpha channel by default: read back as 1
    }
    Image back = round_trip(im, "codes.png");
    for (size_t i = 0; i < im.rgba.size(); ++i)
        EXPECT_EQ(back.rgba[i], i % 4 == 3 ? 1.0f : im.rgba[i]) << i;
}

TEST_F(ImageIoTest, PngRoundsToNearestAndClamps) {
    Image im = ramp_image(-0.2f, 1.3f);
    im.rgba[5] = 0.5f;            // 127.5 rounds up to 128
    im.rgba[6] = 0.5f / 255.0f;   // 0.5 rounds up to 1
    im.rgba[8] = 0.49f / 255.0f;  // 0.49 rounds down to 0
    Image back = round_trip(im, "ramp.png");
    for (size_t i = 0; i < im.rgba.size(); ++i)
        EXPECT_EQ(back.rgba[i], i % 4 == 3 ? 1.0f : code8(im.rgba[i])) << i;
    EXPECT_FLOAT_EQ(back.rgba[5] * 255.0f, 128.0f);
    EXPECT_FLOAT_EQ(back.rgba[6] * 255.0f, 1.0f);
    EXPECT_FLOAT_EQ(back.rgba[8] * 255.0f, 0.0f);
    EXPECT_EQ(back.rgba[0], 0.0f);
    EXPECT_EQ(back.rgba.back(), 1.0f);
}

TEST_F(ImageIoTest, PngSrgbEncodesColourNotAlpha) {
    Image im(4, 1);
    const float values[4] = {0.5f, 0.0f, 1.0f, 0.001f};
    for (int x = 0; x < 4; ++x) {
        float* p = im.pixel(x, 0);
        p[0] = p[1] = p[2] = 0.5f * values[x];  // premultiplied: the file gets values[x] exactly
        p[3] = 0.5f;
    }
    Image back = round_trip(im, "srgb.png", /*srgb=*/true, /*alpha=*/true);
    EXPECT_FLOAT_EQ(back.pixel(0, 0)[0] * 255.0f, 188.0f);  // 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354
    EXPECT_FLOAT_EQ(back.pixel(1, 0)[1] * 255.0f, 0.0f);
    EXPECT_FLOAT_EQ(back.pixel(2, 0)[2] * 255.0f, 255.0f);
    // The linear segment: 12.92 * 0.001 * 255 = 3.29.
    EXPECT_FLOAT_EQ(back.pixel(3, 0)[0] * 255.0f, 3.0f);
    for (int x = 0; x < 4; ++x) EXPECT_FLOAT_EQ(back.pixel(x, 0)[3] * 255.0f, 128.0f);
}

TEST_F(ImageIoTest, ExrKeepsFloatsExactly) {
    Image im(3, 2);
    const float values[] = {0.0f,     1.0f,   1e5f, -3.25f, 1e-20f, 0.1f,  7.0f / 3.0f, -1e-8f,
                            65504.0f, 1e30f,  0.5f, 0.25f,  2.0f,   -0.0f, 3.0f,        0.75f,
                            1.5f,     0.125f, 9.0f, 0.3f,   0.7f,   1.1f,  123.456f,    0.0078125f};
    for (size_t i = 0; i < im.rgba.size(); ++i) im.rgba[i] = values[i];
    // With alpha the premultiplied colour is stored as it is (EXR's convention).
    Image back = round_trip(im, "floats.exr", false, /*alpha=*/true);
    for (size_t i = 0; i < im.rgba.size(); ++i) EXPECT_EQ(back.rgba[i], im.rgba[i]) << i;
    Image rgb = round_trip(im, "rgb.exr");
    for (size_t i = 0; i < im.rgba.size(); ++i)
        EXPECT_EQ(rgb.rgba[i], i % 4 == 3 ? 1.0f : im.rgba[i]) << i;
}

TEST_F(ImageIoTest, NonFiniteValuesNeverReachTheFile) {
    Image im(2, 1);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    float* a = im.pixel(0, 0);
    a[0] = nan, a[1] = inf, a[2] = -inf, a[3] = nan;
    float* b = im.pixel(1, 0);
    b[0] = 0.25f, b[1] = 0.5f, b[2] = 0.75f, b[3] = 1.0f;

    Image exr = round_trip(im, "nan.exr", false, /*alpha=*/true);
    EXPECT_EQ(exr.pixel(0, 0)[0], 0.0f);
    EXPECT_EQ(exr.pixel(0, 0)[1], std::numeric_limits<float>::max());
    EXPECT_EQ(exr.pixel(0, 0)[2], std::numeric_limits<float>::lowest());
    EXPECT_EQ(exr.pixel(0, 0)[3], 0.0f);

    Image png = round_trip(im, "nan.png");
    EXPECT_EQ(png.pixel(0, 0)[0], 0.0f);
    EXPECT_EQ(png.pixel(0, 0)[1], 1.0f);
    EXPECT_EQ(png.pixel(0, 0)[2], 0.0f);
    EXPECT_EQ(png.pixel(0, 0)[3], 1.0f);  // RGB: no alpha stored
    for (float v : png.rgba) EXPECT_TRUE(std::isfinite(v));
}

TEST_F(ImageIoTest, TiffStoresSixteenBitCodes) {
    Image im = ramp_image(-0.1f, 1.1f);
    Image back = round_trip(im, "ramp.tif");
    for (size_t i = 0; i < im.rgba.size(); ++i) {
        const double v = i % 4 == 3 ? 1.0 : std::clamp(double(im.rgba[i]), 0.0, 1.0);
        EXPECT_EQ(back.rgba[i], float(std::floor(v * 65535.0 + 0.5)) / 65535.0f) << i;
    }
}

TEST_F(ImageIoTest, FormatsWithoutAlphaReadBackOpaque) {
    Image im(8, 8);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            float* p = im.pixel(x, y);
            p[0] = 0.2f, p[1] = 0.6f, p[2] = 0.9f, p[3] = 0.0f;
        }
    Image ppm = round_trip(im, "flat.ppm");
    Image jpg = round_trip(im, "flat.jpg");
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x)
            for (int c = 0; c < 3; ++c) {
                EXPECT_EQ(ppm.pixel(x, y)[c], code8(im.pixel(x, y)[c]));
                EXPECT_NEAR(jpg.pixel(x, y)[c], im.pixel(x, y)[c], 2.5 / 255);  // lossy
            }
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            EXPECT_EQ(ppm.pixel(x, y)[3], 1.0f);
            EXPECT_EQ(jpg.pixel(x, y)[3], 1.0f);
        }
}

TEST_F(ImageIoTest, HdrKeepsLargeValuesAndDropsNegatives) {
    Image im(2, 1);
    float* a = im.pixel(0, 0);
    a[0] = 1000.0f, a[1] = 1.5f, a[2] = -2.0f, a[3] = 0.5f;
    float* b = im.pixel(1, 0);
    b[0] = 0.25f, b[1] = 0.25f, b[2] = 0.25f, b[3] = 1.0f;
    Image back = round_trip(im, "big.hdr");
    // RGBE: an 8-bit mantissa under an exponent shared by the pixel.
    EXPECT_NEAR(back.pixel(0, 0)[0], 1000.0f, 1000.0f / 128);
    EXPECT_NEAR(back.pixel(0, 0)[1], 1.5f, 1000.0f / 128);
    EXPECT_EQ(back.pixel(0, 0)[2], 0.0f);
    EXPECT_EQ(back.pixel(0, 0)[3], 1.0f);
    EXPECT_NEAR(back.pixel(1, 0)[0], 0.25f, 0.25f / 128);
}

TEST_F(ImageIoTest, ReadsGreyAndGreyAlphaFiles) {
    for (int nch : {1, 2}) {
        const std::string name = path("grey" + std::to_string(nch) + ".png");
        // Written by OpenImageIO (through the module; with 2 channels the second is alpha).
        const unsigned char pixels[6] = {0, 51, 102, 153, 204, 255};
        std::string error;
        ASSERT_TRUE(oiio_write_pixels(name, 3, 1, nch, VR_OIIO_UINT8, pixels, false, error))
            << error;

        Image im;
        ASSERT_TRUE(read_image(name, im, error)) << error;
        ASSERT_EQ(im.width, 3);
        for (int x = 0; x < 3; ++x) {
            const float grey = float(pixels[x * nch]) / 255.0f;
            const float alpha = nch == 2 ? float(pixels[x * nch + 1]) / 255.0f : 1.0f;
            for (int c = 0; c < 3; ++c) EXPECT_EQ(im.pixel(x, 0)[c], grey) << nch << " " << x;
            EXPECT_EQ(im.pixel(x, 0)[3], alpha) << nch << " " << x;
        }
    }
}

TEST_F(ImageIoTest, ExtensionIsCaseInsensitive) {
    Image im = ramp_image(0.0f, 1.0f);
    Image back = round_trip(im, "UPPER.PNG");
    for (size_t i = 0; i < im.rgba.size(); ++i)
        EXPECT_EQ(back.rgba[i], i % 4 == 3 ? 1.0f : code8(im.rgba[i]));
}

TEST_F(ImageIoTest, WriteErrorsNameTheFile) {
    Image im(2, 2);
    std::string error;
    const std::string unknown = path("picture.notaformat");
    EXPECT_FALSE(write_image(unknown, im, false, error));
    EXPECT_NE(error.find(unknown), std::string::npos) << error;

    error.clear();
    const std::string no_ext = path("picture");
    EXPECT_FALSE(write_image(no_ext, im, false, error));
    EXPECT_NE(error.find(no_ext), std::string::npos) << error;

    error.clear();
    const std::string missing_dir = path("no/such/dir/out.png");
    EXPECT_FALSE(write_image(missing_dir, im, false, error));
    EXPECT_NE(error.find(missing_dir), std::string::npos) << error;

    error.clear();
    EXPECT_FALSE(write_image(path("empty.png"), Image(), false, error));
    EXPECT_NE(error.find("empty.png"), std::string::npos) << error;
}

// Re-rendering to the same file is the common case; the writers overwrite it in place rather than
// truncate it first (the kernel frees and refills the old pages: 2.5 of 6.3 ms for a 1920x1080
// PPM). What ends up in the file must be the new image alone: an old file longer than the new
// image loses its tail, a shorter one grows.
TEST_F(ImageIoTest, OverwritingAFileLeavesTheNewImageOnly) {
    const Image im = ramp_image(0.0f, 1.0f);
    Image8 im8;
    im8.width = 4, im8.height = 3, im8.channels = 3;
    for (int i = 0; i < 4 * 3 * 3; ++i) im8.samples.push_back(uint8_t(7 * i));
    auto bytes = [](const std::string& file) {
        std::ifstream in(file, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    };
    for (const char* name : {"over.png", "over.ppm"}) {
        std::string error;
        const std::string fresh = path(std::string("fresh_") + name);
        ASSERT_TRUE(write_image(fresh, im, WriteOptions{}, error)) << error;
        const std::string expected = bytes(fresh);
        for (size_t old_size : {size_t(1) << 20, size_t(5)}) {
            const std::string target = path(name);
            std::ofstream(target, std::ios::binary) << std::string(old_size, 'x');
            ASSERT_TRUE(write_image(target, im, WriteOptions{}, error)) << error;
            EXPECT_EQ(bytes(target), expected) << name << " over " << old_size << " bytes";
        }
    }
    std::string error;
    const std::string fresh8 = path("fresh8.ppm"), target8 = path("over8.ppm");
    ASSERT_TRUE(write_image8(fresh8, im8, false, error)) << error;
    std::ofstream(target8, std::ios::binary) << std::string(size_t(1) << 20, 'x');
    ASSERT_TRUE(write_image8(target8, im8, false, error)) << error;
    EXPECT_EQ(bytes(target8), bytes(fresh8));
}

// docs/manual.md, render: no alpha channel unless asked for, in any format.
TEST_F(ImageIoTest, EveryFormatIsRgbByDefault) {
    Image im = ramp_image(0.0f, 1.0f);
    for (const char* name : {"rgb.png", "rgb.tif", "rgb.exr", "rgb.tga"}) {
        std::string error;
        ASSERT_TRUE(write_image(path(name), im, false, error)) << error;
        OiioPixels pixels;
        ASSERT_TRUE(oiio_read_pixels(path(name), INT_MAX, kMaxImagePixels, pixels, error)) << error;
        EXPECT_EQ(pixels.channels, 3) << name;
        EXPECT_EQ(pixels.alpha_channel, -1) << name;
    }
}

// With alpha: straight colour in PNG and TIFF (colour / alpha), premultiplied in EXR, and formats
// without alpha refuse.
TEST_F(ImageIoTest, AlphaIsStraightInPngAndTiffPremultipliedInExr) {
    Image im(3, 1);
    const float alphas[3] = {0.5f, 0.25f, 0.0f};
    for (int x = 0; x < 3; ++x) {
        float* p = im.pixel(x, 0);
        p[0] = 0.6f * alphas[x], p[1] = 0.2f * alphas[x], p[2] = alphas[x], p[3] = alphas[x];
    }
    for (const char* name : {"a.png", "a.tif"}) {
        Image back = round_trip(im, name, false, true);
        for (int x = 0; x < 2; ++x) {
            // Half a code of 8 bits (PNG) bounds the rounding; TIFF's 16 bits are finer.
            EXPECT_NEAR(back.pixel(x, 0)[0], 0.6f, 0.5 / 255 + 1e-6) << name << " " << x;
            EXPECT_NEAR(back.pixel(x, 0)[1], 0.2f, 0.5 / 255 + 1e-6) << name << " " << x;
            EXPECT_EQ(back.pixel(x, 0)[2], 1.0f) << name << " " << x;
            EXPECT_NEAR(back.pixel(x, 0)[3], alphas[x], 0.5 / 255 + 1e-6) << name << " " << x;
        }
        for (int c = 0; c < 4; ++c)
            EXPECT_EQ(back.pixel(2, 0)[c], 0.0f) << name;  // alpha 0: colour 0
    }
    Image exr = round_trip(im, "a.exr", false, true);
    for (size_t i = 0; i < im.rgba.size(); ++i) EXPECT_EQ(exr.rgba[i], im.rgba[i]) << i;
    for (const char* name : {"a.jpg", "a.ppm", "a.hdr"}) {
        std::string error;
        EXPECT_FALSE(write_image(path(name), im, WriteOptions{false, true}, error)) << name;
        EXPECT_NE(error.find("alpha"), std::string::npos) << error;
        EXPECT_FALSE(fs::exists(path(name))) << name;
    }
}

// What vrmlray render asks before it reads the scene: nothing is created, and each failure says
// why.
TEST_F(ImageIoTest, OutputIsCheckedBeforeWriting) {
    std::string error;
    EXPECT_EQ(check_output(path("ok.png"), false, error), OutputCheck::kOk) << error;
    EXPECT_EQ(check_output(path("ok.exr"), true, error), OutputCheck::kOk) << error;
    EXPECT_EQ(check_output(path("ok.tif"), true, error), OutputCheck::kOk) << error;
    EXPECT_EQ(check_output(path("ok.jpg"), false, error), OutputCheck::kOk) << error;
    EXPECT_EQ(check_output(path("x.bogus"), false, error), OutputCheck::kNotWritable);
    EXPECT_NE(error.find("unknown image format '.bogus'"), std::string::npos) << error;
    EXPECT_EQ(check_output(path("no/such/dir/x.png"), false, error), OutputCheck::kNotWritable);
    EXPECT_NE(error.find("does not exist"), std::string::npos) << error;
    EXPECT_EQ(check_output(path("noext"), false, error), OutputCheck::kNotWritable);
    EXPECT_EQ(check_output(dir_.string() + "/", false, error), OutputCheck::kNotWritable);
    for (const char* name : {"x.jpg", "x.ppm", "x.hdr"}) {
        EXPECT_EQ(check_output(path(name), true, error), OutputCheck::kNoAlpha) << name;
        EXPECT_NE(error.find("alpha"), std::string::npos) << error;
    }
    EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(ImageIoTest, ReadErrorsNameTheFile) {
    Image im;
    std::string error;
    const std::string missing = path("missing.png");
    EXPECT_FALSE(read_image(missing, im, error));
    EXPECT_NE(error.find(missing), std::string::npos) << error;

    const std::string garbage = path("garbage.png");
    {
        FILE* f = std::fopen(garbage.c_str(), "wb");
        ASSERT_TRUE(f);
        std::fputs("this is not a png", f);
        std::fclose(f);
    }
    error.clear();
    EXPECT_FALSE(read_image(garbage, im, error));
    EXPECT_NE(error.find(garbage), std::string::npos) << error;
}

}  // namespace
}  // namespace vr
