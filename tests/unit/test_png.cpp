// PNG through libpng (image/png.h): round trips, every colour type, bit depth, filter and
// interlacing against OpenImageIO's reading of the same file (through the module), broken files,
// the texture size limit (issue #7) and loading the OpenImageIO module.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "flatten/flatten.h"
#include "image/image.h"
#include "image/oiio_module.h"
#include "image/png.h"
#include "image/texture_file.h"
#include "parser/load.h"
#include "scene/build.h"

namespace vr {
namespace {

namespace fs = std::filesystem;

class PngTest : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               ("vrmlray_png_" + std::to_string(::getpid()) + "_" + info->name());
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    std::string write_file(const std::string& name, const std::vector<uint8_t>& bytes) const {
        std::ofstream out(path(name), std::ios::binary);
        out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        return path(name);
    }

    fs::path dir_;
};

std::vector<uint8_t> read_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// ---- PNG files built by hand, independently of png.cpp
// -------------------------------------------

void put32(std::vector<uint8_t>& out, uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(v >> s));
}

void add_chunk(std::vector<uint8_t>& png, const char* type, const std::vector<uint8_t>& body) {
    put32(png, uint32_t(body.size()));
    const size_t type_at = png.size();
    png.insert(png.end(), type, type + 4);
    png.insert(png.end(), body.begin(), body.end());
    put32(png, uint32_t(crc32(0L, png.data() + type_at, uInt(4 + body.size()))));
}

int file_channels(int color_type) {
    switch (color_type) {
        case 0:
            return 1;
        case 2:
            return 3;
        case 3:
            return 1;
        case 4:
            return 2;
        default:
            return 4;
    }
}

struct HandPng {
    uint32_t width = 0, height = 0;
    int depth = 8, color_type = 6;
    bool interlaced = false;
    std::vector<uint8_t> plte, trns;
    std::vector<std::vector<uint32_t>> values;  // per row: width * channels sample values
};

// Packs one row of sample values at the file's bit depth (16-bit big-endian, low depths MSB first).
std::vector<uint8_t> pack_row(const HandPng& p, const std::vector<uint32_t>& v) {
    std::vector<uint8_t> out;
    if (p.depth == 16) {
        for (uint32_t s : v) out.push_back(uint8_t(s >> 8)), out.push_back(uint8_t(s));
    } else if (p.depth == 8) {
        for (uint32_t s : v) out.push_back(uint8_t(s));
    } else {
        out.assign((v.size() * p.depth + 7) / 8, 0);
        for (size_t i = 0; i < v.size(); ++i)
            out[i * p.depth / 8] |= uint8_t(v[i] << (8 - p.depth - int(i * p.depth % 8)));
    }
    return out;
}

int paeth(int a, int b, int c) {
    const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

// Filter byte + filtered bytes, filter `f` (0..4), previous row `prev` (zeros for the first).
std::vector<uint8_t> filter_row(const std::vector<uint8_t>& cur, const std::vector<uint8_t>& prev,
                                size_t bpp, int f) {
    std::vector<uint8_t> out{uint8_t(f)};
    for (size_t i = 0; i < cur.size(); ++i) {
        const int a = i >= bpp ? cur[i - bpp] : 0, b = prev[i], c = i >= bpp ? prev[i - bpp] : 0;
        const int pred = f == 0   ? 0
                         : f == 1 ? a
                         : f == 2 ? b
                         : f == 3 ? (a + b) / 2
                                  : paeth(a, b, c);
        out.push_back(uint8_t(cur[i] - pred));
    }
    return out;
}

// Row r of the image uses filter r % 5, so every filter meets every kind of row.
std::vector<uint8_t> filtered_image(const HandPng& p) {
    const size_t bpp = std::max(1, file_channels(p.color_type) * p.depth / 8);
    std::vector<uint8_t> out;
    auto add_rows = [&](const std::vector<std::vector<uint32_t>>& rows) {
        std::vector<uint8_t> prev;
        for (size_t y = 0; y < rows.size(); ++y) {
            const std::vector<uint8_t> cur = pack_row(p, rows[y]);
            if (prev.empty()) prev.assign(cur.size(), 0);
            const auto f = filter_row(cur, prev, bpp, int(y % 5));
            out.insert(out.end(), f.begin(), f.end());
            prev = cur;
        }
    };
    if (!p.interlaced) {
        add_rows(p.values);
        return out;
    }
    // Adam7: seven sub-images of every (dx, dy)-th pixel from (x0, y0); empty passes are absent.
    const int x0[7] = {0, 4, 0, 2, 0, 1, 0}, y0[7] = {0, 0, 4, 0, 2, 0, 1};
    const int dx[7] = {8, 8, 4, 4, 2, 2, 1}, dy[7] = {8, 8, 8, 4, 4, 2, 2};
    const int ch = file_channels(p.color_type);
    for (int pass = 0; pass < 7; ++pass) {
        std::vector<std::vector<uint32_t>> rows;
        for (uint32_t y = y0[pass]; y < p.height; y += dy[pass]) {
            std::vector<uint32_t> row;
            for (uint32_t x = x0[pass]; x < p.width; x += dx[pass])
                for (int c = 0; c < ch; ++c) row.push_back(p.values[y][x * ch + c]);
            if (!row.empty()) rows.push_back(row);
        }
        add_rows(rows);
    }
    return out;
}

std::vector<uint8_t> build_png(const HandPng& p, int idat_pieces = 1) {
    std::vector<uint8_t> png = {137, 80, 78, 71, 13, 10, 26, 10};
    std::vector<uint8_t> ihdr;
    put32(ihdr, p.width);
    put32(ihdr, p.height);
    ihdr.insert(ihdr.end(), {uint8_t(p.depth), uint8_t(p.color_type), 0, 0, uint8_t(p.interlaced)});
    add_chunk(png, "IHDR", ihdr);
    if (!p.plte.empty()) add_chunk(png, "PLTE", p.plte);
    if (!p.trns.empty()) add_chunk(png, "tRNS", p.trns);
    const std::vector<uint8_t> raw = filtered_image(p);
    uLongf size = compressBound(uLong(raw.size()));
    std::vector<uint8_t> z(size);
    EXPECT_EQ(compress2(z.data(), &size, raw.data(), uLong(raw.size()), 9), Z_OK);
    z.resize(size);
    const size_t piece = (z.size() + idat_pieces - 1) / idat_pieces;
    for (size_t at = 0; at < z.size(); at += piece)
        add_chunk(png, "IDAT",
                  std::vector<uint8_t>(z.begin() + ptrdiff_t(at),
                                       z.begin() + ptrdiff_t(std::min(z.size(), at + piece))));
    add_chunk(png, "IEND", {});
    return png;
}

// Random sample values (every third pixel set to `key` when given, to meet tRNS).
HandPng random_png(uint32_t w, uint32_t h, int depth, int color_type, uint32_t seed,
                   const std::vector<uint32_t>& key = {}) {
    HandPng p;
    p.width = w, p.height = h, p.depth = depth, p.color_type = color_type;
    std::mt19937 rng(seed);
    const int ch = file_channels(color_type);
    uint32_t limit = (1u << depth) - 1;
    if (color_type == 3) {
        const int entries = std::min(256, 1 << depth);
        for (int i = 0; i < entries * 3; ++i) p.plte.push_back(uint8_t(rng()));
        limit = uint32_t(entries - 1);
    }
    for (uint32_t y = 0; y < h; ++y) {
        std::vector<uint32_t> row;
        for (uint32_t x = 0; x < w; ++x)
            for (int c = 0; c < ch; ++c)
                row.push_back(!key.empty() && x % 3 == 0 ? key[c] : rng() % (limit + 1));
        p.values.push_back(row);
    }
    return p;
}

std::vector<uint8_t> be16_key(const std::vector<uint32_t>& key) {
    std::vector<uint8_t> out;
    for (uint32_t k : key) out.push_back(uint8_t(k >> 8)), out.push_back(uint8_t(k));
    return out;
}

// A valid 16x16 RGBA image, the starting point of the broken files.
std::vector<uint8_t> small_rgba_png() { return build_png(random_png(16, 16, 8, 6, 7), 3); }

// ---- loading the module ------------------------------------------------------------------------

TEST_F(PngTest, ModuleLoadsFromTheBuildAndFailuresSayWhy) {
    std::string error;
    ASSERT_NE(oiio_module(error), nullptr) << error;

    OiioModule m;
    const std::string missing = path("nowhere/vrmlray_oiio.so");
    EXPECT_FALSE(load_oiio_module({missing}, m, error));
    EXPECT_EQ(error.rfind("the OpenImageIO module " + missing + " could not be loaded: ", 0), 0u)
        << error;
    EXPECT_NE(error.find("No such file"), std::string::npos) << error;

    // A candidate that exists but is no shared object is the headline: its failure is the news.
    const std::string text = write_file("vrmlray_oiio.so", {'n', 'o', 't', '\n'});
    EXPECT_FALSE(load_oiio_module({missing, text}, m, error));
    EXPECT_EQ(error.rfind("the OpenImageIO module " + text + " could not be loaded: ", 0), 0u)
        << error;
    EXPECT_NE(error.find("also tried " + missing), std::string::npos) << error;
}

// ---- round trips and agreement with OpenImageIO -------------------------------------------------

TEST_F(PngTest, WriteReadRoundTripEightAndSixteenBit) {
    std::mt19937 rng(11);
    for (int depth : {8, 16})
        for (int ch = 1; ch <= 4; ++ch) {
            const int w = 37, h = 23;
            const double max = depth == 8 ? 255.0 : 65535.0;
            std::vector<uint8_t> s8(size_t(w) * h * ch);
            std::vector<uint16_t> s16(s8.size());
            for (size_t i = 0; i < s8.size(); ++i) {
                // Smooth with noise, so that every filter wins somewhere.
                const uint32_t v = uint32_t((i * 977) % 65536 + rng() % 300) % 65536;
                s16[i] = uint16_t(v);
                s8[i] = uint8_t(v >> 8);
            }
            const void* samples = depth == 8 ? static_cast<const void*>(s8.data()) : s16.data();
            const std::string name =
                path("rt" + std::to_string(depth) + "_" + std::to_string(ch) + ".png");
            std::string error;
            ASSERT_TRUE(write_png(name, w, h, ch, depth, samples, false, error)) << error;
            PngPixels back;
            ASSERT_EQ(read_png(name, kMaxImagePixels, back, error), PngStatus::kOk) << error;
            ASSERT_EQ(back.width, w);
            ASSERT_EQ(back.height, h);
            ASSERT_EQ(back.channels, ch);
            EXPECT_EQ(back.bit_depth, depth);
            for (size_t i = 0; i < s8.size(); ++i) {
                const float code = depth == 8 ? s8[i] : s16[i];
                ASSERT_EQ(back.samples[i], code / float(max)) << depth << " " << ch << " " << i;
            }
            // OpenImageIO decodes the native file to the same values.
            OiioPixels oiio;
            ASSERT_TRUE(oiio_read_pixels(name, INT_MAX, kMaxImagePixels, oiio, error)) << error;
            ASSERT_EQ(oiio.channels, ch);
            EXPECT_EQ(oiio.samples, back.samples) << depth << " " << ch;
        }
}

TEST_F(PngTest, NativeRenderOutputMatchesOpenImageIO) {
    // What `render -o x.png` writes: 8-bit RGB (RGBA with --alpha), clamped, rounded, alpha
    // unassociated.
    Image im(41, 17);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-0.2f, 1.2f);
    for (float& v : im.rgba) v = u(rng);
    for (bool srgb : {false, true})
        for (bool alpha : {false, true}) {
            const std::string name =
                path(std::string(srgb ? "srgb" : "linear") + (alpha ? "_a.png" : ".png"));
            std::string error;
            ASSERT_TRUE(write_image(name, im, WriteOptions{srgb, alpha}, error)) << error;
            Image native;
            ASSERT_TRUE(read_image(name, native, error)) << error;
            OiioPixels oiio;
            ASSERT_TRUE(oiio_read_pixels(name, INT_MAX, kMaxImagePixels, oiio, error)) << error;
            ASSERT_EQ(oiio.channels, alpha ? 4 : 3);
            EXPECT_EQ(oiio.alpha_channel, alpha ? 3 : -1);
            size_t mismatches = 0;
            for (size_t p = 0; p < size_t(im.width) * im.height; ++p)
                for (int c = 0; c < oiio.channels; ++c)
                    mismatches += oiio.samples[p * oiio.channels + c] != native.rgba[p * 4 + c];
            EXPECT_EQ(mismatches, 0u);
            // OpenImageIO writes these chunks for an sRGB image; the native writer does too.
            const std::vector<uint8_t> bytes = read_file(name);
            const std::string text(bytes.begin(), bytes.end());
            EXPECT_EQ(text.find("sRGB") != std::string::npos, srgb);
            EXPECT_EQ(text.find("gAMA") != std::string::npos, srgb);
            EXPECT_NE(text.find(std::string("Software\0vrmlray", 16)), std::string::npos);
        }
}

TEST_F(PngTest, NativePpmIsByteForByteOpenImageIOs) {
    Image im(5, 3);
    std::vector<uint8_t> codes;
    for (int i = 0; i < 15; ++i) {
        float* p = im.pixel(i % 5, i / 5);
        for (int c = 0; c < 3; ++c) {
            codes.push_back(uint8_t((i * 37 + c * 101) % 256));
            p[c] = float(codes.back()) / 255.0f;
        }
        p[3] = 0.5f;
    }
    std::string error;
    ASSERT_TRUE(write_image(path("native.ppm"), im, false, error)) << error;
    ASSERT_TRUE(
        oiio_write_pixels(path("oiio.ppm"), 5, 3, 3, VR_OIIO_UINT8, codes.data(), false, error))
        << error;
    EXPECT_EQ(read_file(path("native.ppm")), read_file(path("oiio.ppm")));
}

// 8-bit sRGB codes come from a table of where each code starts, not a pow per sample: they must
// equal the formula round(255 * encode(clamp(v))) on every float, so the test puts floats on both
// sides of every code boundary (a few ulps apart), spread over [0, 1], and outside it.
TEST_F(PngTest, EightBitSrgbCodesEqualTheFormula) {
    auto expected = [](float value) {
        double v = std::isnan(value) ? 0.0 : std::clamp(double(value), 0.0, 1.0);
        v = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
        return uint8_t(std::floor(std::clamp(v, 0.0, 1.0) * 255.0 + 0.5));
    };
    std::vector<float> values = {0.0f,   -0.0f,      -1.0f, 1.0f,     2.0f,
                                 1e-45f, 0.0031308f, NAN,   INFINITY, -INFINITY};
    for (int code = 0; code < 255; ++code) {
        // Where code + 1 begins: the linear value whose encoding is (code + 0.5) / 255.
        const double e = (code + 0.5) / 255.0;
        const double boundary = e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
        float f = float(boundary);
        for (int k = 0; k < 8; ++k) f = std::nextafter(f, 0.0f);
        for (int k = 0; k < 17; ++k, f = std::nextafter(f, 2.0f)) values.push_back(f);
    }
    for (uint32_t bits = 0; bits <= 0x3F800000u; bits += 4099) {
        float f;
        std::memcpy(&f, &bits, sizeof f);
        values.push_back(f);
    }
    const int width = 1024, height = int((values.size() + width - 1) / width);
    Image im(width, height);
    for (size_t i = 0; i < size_t(width) * height; ++i)
        for (int c = 0; c < 3; ++c)
            im.rgba[4 * i + c] = values[(i + size_t(c) * 7919) % values.size()];
    std::string error;
    ASSERT_TRUE(write_image(path("srgb.ppm"), im, true, error)) << error;
    const std::vector<uint8_t> bytes = read_file(path("srgb.ppm"));
    const std::string header =
        "P6\n" + std::to_string(width) + " " + std::to_string(height) + "\n255\n";
    ASSERT_EQ(bytes.size(), header.size() + size_t(width) * height * 3);
    size_t mismatches = 0;
    for (size_t i = 0; i < size_t(width) * height; ++i)
        for (int c = 0; c < 3; ++c)
            if (bytes[header.size() + 3 * i + c] != expected(im.rgba[4 * i + c])) ++mismatches;
    EXPECT_EQ(mismatches, 0u) << "of " << values.size() << " values";
}

// Without --srgb, 8-bit codes are round(255 * clamp(v)), NaN 0, computed without branches: they
// must equal the formula on floats a few ulps either side of every rounding boundary, and on the
// specials.
TEST_F(PngTest, EightBitLinearCodesEqualTheFormula) {
    auto expected = [](float value) {
        const double v = std::isnan(value) ? 0.0 : std::clamp(double(value), 0.0, 1.0);
        return uint8_t(std::floor(v * 255.0 + 0.5));
    };
    std::vector<float> values = {0.0f,   -0.0f, -1.0f, 1.0f,     2.0f,
                                 1e-45f, NAN,   -NAN,  INFINITY, -INFINITY};
    for (int code = 0; code < 255; ++code) {
        float f = float((code + 0.5) / 255.0);
        for (int k = 0; k < 8; ++k) f = std::nextafter(f, 0.0f);
        for (int k = 0; k < 17; ++k, f = std::nextafter(f, 2.0f)) values.push_back(f);
    }
    Image im(int(values.size()), 1);
    for (size_t i = 0; i < values.size(); ++i)
        for (int c = 0; c < 4; ++c)
            im.rgba[4 * i + c] = values[(i + size_t(c) * 13) % values.size()];
    std::vector<uint8_t> codes(values.size() * 3);
    encode_8bit(im.rgba.data(), values.size(), 3, false, codes.data());
    size_t mismatches = 0;
    for (size_t i = 0; i < values.size(); ++i)
        for (int c = 0; c < 3; ++c) mismatches += codes[3 * i + c] != expected(im.rgba[4 * i + c]);
    EXPECT_EQ(mismatches, 0u) << "of " << codes.size() << " samples";
}

// Tiles arrive row by row, 16 pixels or fewer at the image's edge: every row length gives the
// formula's codes in exactly its 3 or 4 bytes a pixel, and not one byte past them (the 3-channel
// encoder stores 16 bytes at a time; an overrun would cross into the next tile's pixels).
TEST_F(PngTest, EightBitRowsOfEveryLengthStayInTheirBytes) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-0.2f, 1.2f);
    for (int channels : {3, 4})
        for (size_t n = 1; n <= 70; ++n) {
            std::vector<float> rgba(4 * n);
            // Opaque pixels with 4 channels: the file's colour is then the premultiplied one.
            for (size_t i = 0; i < rgba.size(); ++i)
                rgba[i] = channels == 4 && i % 4 == 3 ? 1.0f : u(rng);
            const size_t used = n * size_t(channels);
            std::vector<uint8_t> out(used + 32, uint8_t(0xA5));
            encode_8bit(rgba.data(), n, channels, false, out.data());
            size_t wrong = 0, past = 0;
            for (size_t i = 0; i < n; ++i)
                for (int c = 0; c < channels; ++c) {
                    const double v = std::clamp(double(rgba[4 * i + size_t(c)]), 0.0, 1.0);
                    wrong += out[i * size_t(channels) + size_t(c)] !=
                             uint8_t(std::floor(v * 255.0 + 0.5));
                }
            for (size_t i = used; i < out.size(); ++i) past += out[i] != 0xA5;
            EXPECT_EQ(wrong, 0u) << n << " pixels, " << channels << " channels";
            EXPECT_EQ(past, 0u) << n << " pixels, " << channels << " channels";
        }
}

// Tiles of one value are encoded once and copied (encode_tile_8bit): the bytes must be those of the
// row-by-row encoding for every kind of tile (one value, including NaN and out-of-range ones; one
// pixel differing, first or last; edge tiles narrower than 16), with and without alpha and sRGB,
// and only a tile of one value may report itself as one.
TEST_F(PngTest, TilesOfOneValueEncodeAsRowByRow) {
    const int width = 37, height = 21;  // 16-pixel tiles leave edges of 5 columns and 5 rows
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(-0.2f, 1.2f);
    const float values[][4] = {
        {0.1f, 0.2f, 0.3f, 1.0f}, {NAN, 2.0f, -1.0f, 0.5f}, {0.7f, 0.7f, 0.7f, 0.0f}};
    for (int channels : {3, 4})
        for (bool srgb : {false, true}) {
            Image8 fast, rows;
            for (Image8* im : {&fast, &rows}) {
                im->width = width, im->height = height, im->channels = channels;
                im->samples.assign(size_t(width) * height * size_t(channels), uint8_t(0));
            }
            int tile = 0;
            for (int y0 = 0; y0 < height; y0 += 16)
                for (int x0 = 0; x0 < width; x0 += 16, ++tile) {
                    const int x1 = std::min(x0 + 16, width), y1 = std::min(y0 + 16, height);
                    const size_t count = size_t(x1 - x0) * size_t(y1 - y0);
                    std::vector<float> rgba(4 * count);
                    const float* v = values[tile % 3];
                    for (size_t k = 0; k < count; ++k) std::copy_n(v, 4, &rgba[4 * k]);
                    const int kind =
                        tile % 4;  // 0: one value; 1: the first differs; 2: the last; 3: random
                    if (kind == 1) rgba[0] = 0.25f;
                    if (kind == 2) rgba[4 * count - 2] = 0.75f;
                    if (kind == 3)
                        for (float& x : rgba) x = u(rng);
                    EXPECT_EQ(encode_tile_8bit(rgba.data(), x0, y0, x1, y1, srgb, fast), kind == 0)
                        << "tile " << tile;
                    for (int y = y0; y < y1; ++y)
                        encode_8bit(
                            &rgba[4 * size_t(y - y0) * size_t(x1 - x0)], size_t(x1 - x0), channels,
                            srgb,
                            &rows.samples[(size_t(y) * width + size_t(x0)) * size_t(channels)]);
                }
            EXPECT_TRUE(fast.samples == rows.samples) << channels << " channels, srgb " << srgb;
        }
}

// vrmlray render encodes PNG and PPM tiles to 8 bits as they are traced (Image8) instead of keeping
// a float image: the files must be byte for byte those of write_image, over odd sizes (a PPM block
// of rows that does not divide the height) and every kind of value (out of range, NaN, infinities).
TEST_F(PngTest, EightBitImagesWriteAsTheFloatImage) {
    const int width = 53, height = 1301;  // 1301 rows: blocks of 412 rows leave 65
    Image im(width, height);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-0.3f, 1.3f);
    const float specials[] = {NAN, INFINITY, -INFINITY, -0.0f, 1e-30f, 1.0f};
    for (size_t i = 0; i < im.rgba.size(); ++i) im.rgba[i] = i % 97 < 6 ? specials[i % 97] : u(rng);
    for (const char* ext : {"png", "ppm"})
        for (bool srgb : {false, true})
            for (bool alpha : {false, true}) {
                if (alpha && std::string(ext) == "ppm") continue;  // PPM has no alpha
                const std::string from_float = path(std::string("float.") + ext),
                                  from_bytes = path(std::string("bytes.") + ext);
                Image8 bytes;
                bytes.width = width;
                bytes.height = height;
                bytes.channels = native_8bit_channels(from_bytes, alpha);
                ASSERT_EQ(bytes.channels, alpha ? 4 : 3);
                bytes.samples.resize(size_t(width) * height * size_t(bytes.channels));
                for (int y = 0; y < height; ++y)  // row by row, as tiles arrive
                    encode_8bit(im.pixel(0, y), size_t(width), bytes.channels, srgb,
                                &bytes.samples[size_t(y) * width * size_t(bytes.channels)]);
                std::string error;
                ASSERT_TRUE(write_image(from_float, im, WriteOptions{srgb, alpha}, error)) << error;
                ASSERT_TRUE(write_image8(from_bytes, bytes, srgb, error)) << error;
                EXPECT_EQ(read_file(from_float), read_file(from_bytes))
                    << ext << " srgb " << srgb << " alpha " << alpha;
            }
    EXPECT_EQ(native_8bit_channels("x.exr"), 0);
    Image8 wrong;  // channels that the format does not store
    wrong.width = wrong.height = 1;
    wrong.channels = 4;
    wrong.samples.assign(4, uint8_t(0));
    std::string error;
    EXPECT_FALSE(write_image8(path("wrong.ppm"), wrong, false, error));
    EXPECT_NE(error.find("malformed"), std::string::npos) << error;
}

TEST_F(PngTest, OpenImageIOWrittenFilesReadNatively) {
    for (int format : {VR_OIIO_UINT8, VR_OIIO_UINT16})
        for (int ch = 1; ch <= 4; ++ch) {
            const int w = 9, h = 5;
            std::vector<uint8_t> s8(size_t(w) * h * ch);
            std::vector<uint16_t> s16(s8.size());
            for (size_t i = 0; i < s8.size(); ++i) {
                s8[i] = uint8_t(i * 29 + 3);
                s16[i] = uint16_t(i * 7919 + 11);
            }
            const std::string name =
                path("oiio" + std::to_string(format) + std::to_string(ch) + ".png");
            std::string error;
            ASSERT_TRUE(oiio_write_pixels(
                name, w, h, ch, format,
                format == VR_OIIO_UINT8 ? static_cast<const void*>(s8.data()) : s16.data(), false,
                error))
                << error;
            PngPixels px;
            ASSERT_EQ(read_png(name, kMaxImagePixels, px, error), PngStatus::kOk) << error;
            ASSERT_EQ(px.channels, ch);
            for (size_t i = 0; i < s8.size(); ++i)
                ASSERT_EQ(px.samples[i], format == VR_OIIO_UINT8 ? float(s8[i]) / 255.0f
                                                                 : float(s16[i]) / 65535.0f)
                    << format << " " << ch << " " << i;
        }
}

// Every colour type and bit depth, with and without tRNS, every filter, split IDAT, plain and Adam7
// interlaced: libpng as vrmlray drives it returns exactly what OpenImageIO returns for the file.
TEST_F(PngTest, EveryColourTypeAgreesWithOpenImageIO) {
    struct Case {
        int color_type, depth;
        std::vector<uint32_t> key;  // tRNS key (grey / RGB); for palettes, nonempty = use tRNS
    };
    const std::vector<Case> cases = {
        {0, 1, {}},  {0, 2, {}},  {0, 4, {}},        {0, 8, {}},
        {0, 16, {}}, {0, 2, {1}}, {0, 8, {77}},      {0, 16, {4000}},
        {2, 8, {}},  {2, 16, {}}, {2, 8, {1, 2, 3}}, {2, 16, {300, 0, 65535}},
        {3, 1, {}},  {3, 2, {}},  {3, 4, {}},        {3, 8, {}},
        {3, 4, {1}}, {3, 8, {1}}, {4, 8, {}},        {4, 16, {}},
        {6, 8, {}},  {6, 16, {}},
    };
    int n = 0;
    for (const bool adam7 : {false, true})
        for (const Case& c : cases) {
            const bool palette = c.color_type == 3;
            HandPng p = random_png(13, 11, c.depth, c.color_type, uint32_t(100 + n),
                                   palette ? std::vector<uint32_t>{} : c.key);
            p.interlaced = adam7;
            if (!c.key.empty()) {
                if (palette)
                    for (size_t i = 0; i < p.plte.size() / 3 / 2 + 1; ++i)
                        p.trns.push_back(uint8_t(i * 40));
                else
                    p.trns = be16_key(c.key);
            }
            const std::string what = "type " + std::to_string(c.color_type) + " depth " +
                                     std::to_string(c.depth) + (c.key.empty() ? "" : " tRNS") +
                                     (adam7 ? " Adam7" : "");
            const std::string name =
                write_file("case" + std::to_string(n++) + ".png", build_png(p, 2));
            PngPixels native;
            std::string error;
            ASSERT_EQ(read_png(name, kMaxImagePixels, native, error), PngStatus::kOk)
                << what << error;
            OiioPixels oiio;
            ASSERT_TRUE(oiio_read_pixels(name, INT_MAX, kMaxImagePixels, oiio, error))
                << what << error;
            EXPECT_EQ(native.width, oiio.width) << what;
            EXPECT_EQ(native.height, oiio.height) << what;
            ASSERT_EQ(native.channels, oiio.channels) << what;
            EXPECT_EQ(native.samples, oiio.samples) << what;
            // And read_image's RGBA of it is OpenImageIO's too (grey replicated, alpha where
            // present).
            Image mine;
            ASSERT_TRUE(read_image(name, mine, error)) << error;
            const int alpha =
                oiio.alpha_channel >= 0 ? oiio.alpha_channel : (oiio.channels == 2 ? 1 : -1);
            for (int i = 0; i < 13 * 11; ++i) {
                const float* s = oiio.samples.data() + size_t(i) * oiio.channels;
                const float grey_or_r = s[0];
                EXPECT_EQ(mine.rgba[size_t(i) * 4], grey_or_r) << what;
                EXPECT_EQ(mine.rgba[size_t(i) * 4 + 3], alpha >= 0 ? s[alpha] : 1.0f) << what;
            }
        }
}

// Adam7 files (every pass non-empty at 11 x 9) decode to the same samples, without the module.
TEST_F(PngTest, InterlacedFilesDecode) {
    HandPng p = random_png(11, 9, 8, 2, 3);
    p.interlaced = true;
    const std::vector<uint8_t> bytes = build_png(p);
    PngPixels px;
    std::string error;
    ASSERT_EQ(decode_png(bytes.data(), bytes.size(), kMaxImagePixels, px, error), PngStatus::kOk)
        << error;
    ASSERT_EQ(px.channels, 3);
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 33; ++x)
            ASSERT_EQ(px.samples[size_t(y) * 33 + size_t(x)], float(p.values[y][x]) / 255.0f);
    const std::string name = write_file("adam7.png", bytes);
    Image im;
    ASSERT_TRUE(read_image(name, im, error)) << error;
    ASSERT_EQ(im.width, 11);
    ASSERT_EQ(im.height, 9);
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 11; ++x)
            for (int c = 0; c < 3; ++c)
                ASSERT_EQ(im.pixel(x, y)[c], float(p.values[y][x * 3 + c]) / 255.0f)
                    << x << " " << y;
    ImageData tex;
    ASSERT_TRUE(read_image_file(name, tex, error)) << error;
    EXPECT_EQ(tex.channels, 3);
    EXPECT_EQ(tex.texels[0], float(p.values[8][0]) / 255.0f);  // bottom row first
}

// ---- broken files: an error, never a crash
// -------------------------------------------------------

PngStatus decode(const std::vector<uint8_t>& bytes, std::string& error,
                 size_t max = kMaxImagePixels) {
    PngPixels px;
    error.clear();
    const PngStatus s = decode_png(bytes.data(), bytes.size(), max, px, error);
    if (s == PngStatus::kOk) {
        EXPECT_EQ(px.samples.size(), size_t(px.width) * px.height * px.channels);
    }
    if (s == PngStatus::kError) {
        EXPECT_FALSE(error.empty());
    }
    return s;
}

TEST_F(PngTest, TruncatedFilesAreErrors) {
    const std::vector<uint8_t> png = small_rgba_png();
    std::string error;
    ASSERT_EQ(decode(png, error), PngStatus::kOk) << error;
    for (size_t cut = 0; cut < png.size(); ++cut) {
        const std::vector<uint8_t> part(png.begin(), png.begin() + ptrdiff_t(cut));
        const PngStatus s = decode(part, error);
        if (cut < 8)
            EXPECT_EQ(s, PngStatus::kNotPng) << cut;
        else if (cut < png.size() - 12)  // only a missing IEND is forgiven
            EXPECT_EQ(s, PngStatus::kError) << cut;
        else
            EXPECT_EQ(s, PngStatus::kOk) << cut << " " << error;
    }
    // Through the file reader too, with the file's name in read_image's message.
    const std::string name = write_file(
        "cut.png", std::vector<uint8_t>(png.begin(), png.begin() + ptrdiff_t(png.size() / 2)));
    Image im;
    EXPECT_FALSE(read_image(name, im, error));
    EXPECT_NE(error.find(name), std::string::npos) << error;
    EXPECT_NE(error.find("truncated"), std::string::npos) << error;
}

TEST_F(PngTest, BadCrcIsAnErrorInCriticalChunksOnly) {
    std::vector<uint8_t> png = small_rgba_png();
    std::string error;
    // The first IDAT's data starts after the signature, IHDR (25) and the IDAT header (8). libpng
    // inflates a chunk's data before it reaches its CRC: damaged data is reported as such.
    std::vector<uint8_t> bad = png;
    bad[8 + 25 + 8 + 5] ^= 0x10;
    EXPECT_EQ(decode(bad, error), PngStatus::kError);
    EXPECT_NE(error.find("IDAT"), std::string::npos) << error;
    // Intact data under a wrong CRC: the CRC is the news.
    const size_t idat_length =
        size_t(png[33]) << 24 | size_t(png[34]) << 16 | size_t(png[35]) << 8 | png[36];
    bad = png;
    bad[33 + 8 + idat_length] ^= 0x01;
    EXPECT_EQ(decode(bad, error), PngStatus::kError);
    EXPECT_NE(error.find("CRC"), std::string::npos) << error;
    EXPECT_NE(error.find("IDAT"), std::string::npos) << error;

    // A damaged ancillary chunk is dropped, as libpng does.
    std::vector<uint8_t> with_text(png.begin(), png.begin() + 33);
    add_chunk(with_text, "tEXt", {'a', 0, 'b'});
    with_text.back() ^= 1;
    with_text.insert(with_text.end(), png.begin() + 33, png.end());
    EXPECT_EQ(decode(with_text, error), PngStatus::kOk) << error;
}

TEST_F(PngTest, BadCompressedDataIsAnError) {
    HandPng p = random_png(8, 8, 8, 2, 1);
    std::vector<uint8_t> png = {137, 80, 78, 71, 13, 10, 26, 10};
    const std::vector<uint8_t> good = build_png(p);
    png.insert(png.end(), good.begin() + 8, good.begin() + 33);  // IHDR
    add_chunk(png, "IDAT", {0x78, 0x9c, 0xff, 0xff, 0xff, 0xff, 0x12, 0x34, 0x56});
    add_chunk(png, "IEND", {});
    std::string error;
    EXPECT_EQ(decode(png, error), PngStatus::kError);
    EXPECT_NE(error.find("compressed"), std::string::npos) << error;

    // A zlib stream that ends before the image does.
    std::vector<uint8_t> raw(20, 0);
    uLongf size = compressBound(20);
    std::vector<uint8_t> z(size);
    ASSERT_EQ(compress2(z.data(), &size, raw.data(), 20, 6), Z_OK);
    z.resize(size);
    std::vector<uint8_t> short_png(good.begin(), good.begin() + 33);
    add_chunk(short_png, "IDAT", z);
    add_chunk(short_png, "IEND", {});
    EXPECT_EQ(decode(short_png, error), PngStatus::kError);
    EXPECT_NE(error.find("truncated"), std::string::npos) << error;

    // A filter type beyond 4.
    std::vector<uint8_t> rows(8 * (1 + 24), 0);
    rows[25] = 7;
    size = compressBound(uLong(rows.size()));
    z.assign(size, 0);
    ASSERT_EQ(compress2(z.data(), &size, rows.data(), uLong(rows.size()), 6), Z_OK);
    z.resize(size);
    std::vector<uint8_t> bad_filter(good.begin(), good.begin() + 33);
    add_chunk(bad_filter, "IDAT", z);
    add_chunk(bad_filter, "IEND", {});
    EXPECT_EQ(decode(bad_filter, error), PngStatus::kError);
    EXPECT_NE(error.find("filter"), std::string::npos) << error;
}

TEST_F(PngTest, HugeClaimedSizesAllocateNothing) {
    const std::vector<uint8_t> good = small_rgba_png();
    auto claim = [&](uint32_t w, uint32_t h, int depth, int type) {
        std::vector<uint8_t> png = {137, 80, 78, 71, 13, 10, 26, 10};
        std::vector<uint8_t> ihdr;
        put32(ihdr, w);
        put32(ihdr, h);
        ihdr.insert(ihdr.end(), {uint8_t(depth), uint8_t(type), 0, 0, 0});
        add_chunk(png, "IHDR", ihdr);
        png.insert(png.end(), good.begin() + 33, good.end());  // a small image's data
        return png;
    };
    std::string error;
    // Over the pixel limit: refused from the header.
    EXPECT_EQ(decode(claim(100000, 100000, 8, 6), error), PngStatus::kError);
    EXPECT_NE(error.find("too large (100000 x 100000"), std::string::npos) << error;
    EXPECT_EQ(decode(claim(0x7fffffff, 0x7fffffff, 16, 6), error, SIZE_MAX), PngStatus::kError);
    // Under the limit but more than the data could inflate to: refused before allocating 2 GB.
    EXPECT_EQ(decode(claim(16000, 16000, 16, 6), error), PngStatus::kError);
    EXPECT_NE(error.find("too short"), std::string::npos) << error;
    // Width beyond the specification's 2^31 - 1, zero, bad depth for the type, unknown type.
    EXPECT_EQ(decode(claim(0x80000000u, 1, 8, 6), error, SIZE_MAX), PngStatus::kError);
    EXPECT_EQ(decode(claim(0, 16, 8, 6), error), PngStatus::kError);
    EXPECT_EQ(decode(claim(16, 16, 4, 6), error), PngStatus::kError);
    EXPECT_EQ(decode(claim(16, 16, 8, 5), error), PngStatus::kError);
    // A palette image without its palette.
    EXPECT_EQ(decode(claim(16, 16, 8, 3), error), PngStatus::kError);
    EXPECT_NE(error.find("PLTE"), std::string::npos) << error;
}

TEST_F(PngTest, RandomDamageNeverCrashes) {
    HandPng pal = random_png(19, 13, 4, 3, 9);
    pal.trns = {0, 128, 255};
    const std::vector<std::vector<uint8_t>> seeds = {small_rgba_png(), build_png(pal, 2),
                                                     build_png(random_png(7, 30, 16, 0, 4))};
    std::mt19937 rng(2024);
    std::string error;
    for (int i = 0; i < 3000; ++i) {
        std::vector<uint8_t> png = seeds[size_t(i) % seeds.size()];
        const int flips = 1 + int(rng() % 4);
        for (int f = 0; f < flips; ++f) png[8 + rng() % (png.size() - 8)] = uint8_t(rng());
        if (i % 2 == 0) {
            // Recompute every CRC, so the damage reaches the chunk contents' checks.
            for (size_t pos = 8; pos + 12 <= png.size();) {
                const uint32_t len = uint32_t(png[pos]) << 24 | uint32_t(png[pos + 1]) << 16 |
                                     uint32_t(png[pos + 2]) << 8 | png[pos + 3];
                if (len > png.size() - pos - 12) break;
                const uint32_t crc = uint32_t(crc32(0L, png.data() + pos + 4, uInt(4 + len)));
                for (int b = 0; b < 4; ++b) png[pos + 8 + len + b] = uint8_t(crc >> (24 - 8 * b));
                pos += 12 + len;
            }
        }
        decode(png, error);
    }
}

// ---- texture size limit (issue #7)
// ---------------------------------------------------------------

TEST_F(PngTest, TextureSizeLimitIsCheckedFromTheHeader) {
    const std::string name = write_file("wide.png", build_png(random_png(64, 32, 8, 6, 8)));
    ImageData tex;
    std::string error;
    EXPECT_FALSE(read_image_file(name, tex, error, 64 * 32 - 1));
    EXPECT_NE(error.find("too large (64 x 32 = 2048 pixels; the limit is 2047)"), std::string::npos)
        << error;
    EXPECT_TRUE(tex.texels.empty());
    ASSERT_TRUE(read_image_file(name, tex, error, 64 * 32)) << error;
    EXPECT_EQ(tex.width, 64);
    EXPECT_EQ(tex.channels, 4);

    // A header claiming 20000 x 20000 is refused by the default limit... (4e8 > 2^28)
    std::vector<uint8_t> huge = {137, 80, 78, 71, 13, 10, 26, 10};
    std::vector<uint8_t> ihdr;
    put32(ihdr, 20000);
    put32(ihdr, 20000);
    ihdr.insert(ihdr.end(), {8, 6, 0, 0, 0});
    add_chunk(huge, "IHDR", ihdr);
    add_chunk(huge, "IEND", {});
    EXPECT_FALSE(read_image_file(write_file("huge.png", huge), tex, error));
    EXPECT_NE(error.find("20000 x 20000"), std::string::npos) << error;
}

TEST_F(PngTest, FlattenIgnoresTexturesOverTheLimitWithAWarning) {
    // Rows from the top: the first row is opaque red, the last half-transparent green.
    HandPng p;
    p.width = 4, p.height = 2, p.depth = 8, p.color_type = 6;
    p.values = {{255, 0, 0, 255, 255, 0, 0, 255, 255, 0, 0, 255, 255, 0, 0, 255},
                {0, 255, 0, 128, 0, 255, 0, 128, 0, 255, 0, 128, 0, 255, 0, 128}};
    write_file("tex.png", build_png(p));
    const std::string scene_path = path("scene.wrl");
    const std::string text =
        "#VRML V2.0 utf8\n"
        "Shape { appearance Appearance { texture ImageTexture { url \"tex.png\" } } geometry Box "
        "{} }\n";
    for (size_t limit : {size_t(7), size_t(8)}) {
        LoadedScene loaded = load_scene_text(text, scene_path);
        ASSERT_TRUE(loaded.ok());
        Diagnostics diagnostics;
        const Scene scene = build_scene(loaded, diagnostics);
        FlattenOptions options;
        options.scene_file = scene_path;
        options.max_texture_pixels = limit;
        FlattenStats stats;
        const FlatScene flat = flatten_scene(scene, options, diagnostics, stats);
        bool warned = false;
        for (const Diagnostic& d : diagnostics.all())
            warned =
                warned || (d.message.find("tex.png") != std::string::npos &&
                           d.message.find("4 x 2 = 8 pixels; the limit is 7") != std::string::npos);
        if (limit == 7) {
            EXPECT_TRUE(warned);
            EXPECT_TRUE(flat.textures.empty());
        } else {
            EXPECT_FALSE(warned);
            ASSERT_EQ(flat.textures.size(), 1u);
            const Texture& t = flat.textures[0];
            EXPECT_EQ(t.channels, 4);
            // Bottom row first, colour not multiplied by alpha.
            EXPECT_EQ(t.texels[1], 1.0f);
            EXPECT_EQ(t.texels[3], 128.0f / 255.0f);
            EXPECT_EQ(t.texels[4 * 4], 1.0f);
        }
    }
}

// The golden images were written by the hand-written PNG writer that libpng replaced (filter per
// row by the smallest sum of absolute bytes, zlib level 6, filtered strategy). Re-encoding each one
// must give the same pixels in no more bytes: libpng's default strategy alone was 5.9% larger on
// the gas golden, which is why both strategies are tried.
TEST_F(PngTest, EveryGoldenReencodesInNoMoreBytesThanTheHandWrittenWriter) {
    const std::filesystem::path golden =
        std::filesystem::path(VRMLRAY_SOURCE_DIR) / "tests/render/golden";
    int checked = 0;
    for (const auto& entry : std::filesystem::directory_iterator(golden)) {
        if (entry.path().extension() != ".png") continue;
        SCOPED_TRACE(entry.path().filename().string());
        PngPixels in;
        std::string error;
        ASSERT_EQ(read_png(entry.path().string(), 1u << 24, in, error), PngStatus::kOk) << error;
        ASSERT_EQ(in.bit_depth, 8);
        std::vector<uint8_t> codes(in.samples.size());
        for (size_t i = 0; i < codes.size(); ++i)
            codes[i] = uint8_t(std::lround(in.samples[i] * 255.0f));
        const std::string out = (dir_ / "reencoded.png").string();
        // Renders are written without the sRGB chunks, as the goldens were.
        ASSERT_TRUE(write_png(out, in.width, in.height, in.channels, 8, codes.data(), false, error))
            << error;
        EXPECT_LE(std::filesystem::file_size(out), entry.file_size());
        PngPixels back;
        ASSERT_EQ(read_png(out, 1u << 24, back, error), PngStatus::kOk) << error;
        EXPECT_EQ(back.samples, in.samples);
        ++checked;
    }
    EXPECT_GE(checked, 22);  // every golden of tests/render/golden/golden.txt
}

}  // namespace
}  // namespace vr
