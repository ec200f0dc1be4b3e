#include "image/png.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

namespace vr {
namespace {

constexpr uint8_t kSignature[8] = {137, 80, 78, 71, 13, 10, 26, 10};
constexpr uint32_t kMaxChunkLength =
    0x7fffffffu;  // the specification's limit for lengths and sizes
// Deflate writes a 258-byte match in no fewer than 2 bits once its codes are set up, so no
// stream expands more than ~1032:1; the slack covers the stream and block headers.
constexpr uint64_t kMaxInflateRatio = 1032;
constexpr uint64_t kInflateSlack = 1024;

uint32_t be32(const uint8_t* p) {
    return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

std::string chunk_name(const uint8_t* type) {
    std::string name;
    for (int i = 0; i < 4; ++i) {
        const char c = char(type[i]);
        name += (c >= 33 && c <= 126) ? c : '?';
    }
    return name;
}

bool is_letter(uint8_t c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z'); }

struct Header {
    uint32_t width = 0, height = 0;
    int bit_depth = 0;
    int color_type = 0;
    bool interlaced = false;
    int file_channels = 0;  // samples a pixel as stored (palette: 1 index)
};

bool parse_ihdr(const uint8_t* d, uint32_t length, size_t max_pixels, Header& h,
                std::string& error) {
    if (length != 13) {
        error = "IHDR chunk has length " + std::to_string(length) + ", not 13";
        return false;
    }
    h.width = be32(d);
    h.height = be32(d + 4);
    h.bit_depth = d[8];
    h.color_type = d[9];
    if (h.width == 0 || h.height == 0 || h.width > kMaxChunkLength || h.height > kMaxChunkLength) {
        error = "bad image size " + std::to_string(h.width) + " x " + std::to_string(h.height);
        return false;
    }
    const int depth = h.bit_depth;
    bool depth_ok = false;
    switch (h.color_type) {
        case 0:
            h.file_channels = 1;
            depth_ok = depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16;
            break;
        case 2:
            h.file_channels = 3;
            depth_ok = depth == 8 || depth == 16;
            break;
        case 3:
            h.file_channels = 1;
            depth_ok = depth == 1 || depth == 2 || depth == 4 || depth == 8;
            break;
        case 4:
            h.file_channels = 2;
            depth_ok = depth == 8 || depth == 16;
            break;
        case 6:
            h.file_channels = 4;
            depth_ok = depth == 8 || depth == 16;
            break;
        default:
            error = "unknown colour type " + std::to_string(h.color_type);
            return false;
    }
    if (!depth_ok) {
        error = "bit depth " + std::to_string(depth) + " is not allowed for colour type " +
                std::to_string(h.color_type);
        return false;
    }
    if (d[10] != 0 || d[11] != 0 || d[12] > 1) {
        error = "unknown compression, filter or interlace method";
        return false;
    }
    h.interlaced = d[12] == 1;
    const uint64_t pixels = uint64_t(h.width) * uint64_t(h.height);
    if (pixels > max_pixels) {
        error = "the image is too large (" + std::to_string(h.width) + " x " +
                std::to_string(h.height) + " = " + std::to_string(pixels) +
                " pixels; the limit is " + std::to_string(max_pixels) + ")";
        return false;
    }
    return true;
}

// Everything the chunks say, with the image data as pieces of the input.
struct Chunks {
    Header header;
    std::array<uint8_t, 256 * 3> palette{};
    int palette_entries = 0;
    std::array<uint8_t, 256> palette_alpha{};  // 255 beyond the tRNS entries
    bool has_trns = false;
    uint16_t trns_key[3] = {0, 0, 0};  // grey or RGB value that is transparent
    std::vector<std::pair<const uint8_t*, uint32_t>> idat;
    uint64_t idat_bytes = 0;
};

bool parse_chunks(const uint8_t* data, size_t size, size_t max_pixels, Chunks& c,
                  std::string& error) {
    size_t pos = 8;
    bool have_header = false, idat_done = false;
    c.palette_alpha.fill(255);
    while (true) {
        if (size - pos < 12) {
            // Image data already complete and only IEND missing is accepted (as most readers
            // do); anything shorter is caught by inflate.
            if (have_header && !c.idat.empty()) return true;
            error = "the file is truncated";
            return false;
        }
        const uint32_t length = be32(data + pos);
        const uint8_t* type = data + pos + 4;
        const uint8_t* body = data + pos + 8;
        const std::string name = chunk_name(type);
        if (length > kMaxChunkLength || size - pos - 12 < length) {
            error = "chunk " + name + " is truncated (length " + std::to_string(length) + ")";
            return false;
        }
        if (!is_letter(type[0]) || !is_letter(type[1]) || !is_letter(type[2]) ||
            !is_letter(type[3])) {
            error = "bad chunk type '" + name + "'";
            return false;
        }
        const bool critical = (type[0] & 0x20) == 0;
        const uint32_t stored_crc = be32(body + length);
        const uint32_t crc = uint32_t(crc32(crc32(0L, type, 4), body, length));
        pos += 12 + size_t(length);
        if (crc != stored_crc) {
            // libpng's rule: a damaged critical chunk is an error, a damaged ancillary one is
            // dropped.
            if (critical) {
                error = "bad CRC in chunk " + name;
                return false;
            }
            continue;
        }
        if (!have_header) {
            if (name != "IHDR") {
                error = "the first chunk is " + name + ", not IHDR";
                return false;
            }
            if (!parse_ihdr(body, length, max_pixels, c.header, error)) return false;
            have_header = true;
            continue;
        }
        if (name == "IDAT") {
            if (idat_done) {
                error = "IDAT chunks are not consecutive";
                return false;
            }
            if (length > 0) c.idat.emplace_back(body, length);
            c.idat_bytes += length;
            continue;
        }
        if (!c.idat.empty()) idat_done = true;
        if (name == "IEND") break;
        if (name == "IHDR") {
            error = "a second IHDR chunk";
            return false;
        }
        if (name == "PLTE") {
            if (length == 0 || length % 3 != 0 || length > 256 * 3) {
                error = "PLTE chunk has bad length " + std::to_string(length);
                return false;
            }
            if (!c.idat.empty()) {
                error = "PLTE chunk after the image data";
                return false;
            }
            std::memcpy(c.palette.data(), body, length);
            c.palette_entries = int(length / 3);
        } else if (name == "tRNS") {
            // A malformed tRNS is ignored, as libpng does (with a warning).
            const int type_code = c.header.color_type;
            if (type_code == 0 && length == 2) {
                c.trns_key[0] = uint16_t(body[0] << 8 | body[1]);
                c.has_trns = true;
            } else if (type_code == 2 && length == 6) {
                for (int i = 0; i < 3; ++i)
                    c.trns_key[i] = uint16_t(body[2 * i] << 8 | body[2 * i + 1]);
                c.has_trns = true;
            } else if (type_code == 3 && length > 0 && c.palette_entries > 0) {
                const uint32_t n = std::min<uint32_t>(length, uint32_t(c.palette_entries));
                std::memcpy(c.palette_alpha.data(), body, n);
                c.has_trns = true;
            }
        } else if (critical) {
            error = "unknown critical chunk " + name;
            return false;
        }
    }
    if (!have_header) {
        error = "no IHDR chunk";
        return false;
    }
    if (c.idat.empty()) {
        error = "no image data (IDAT)";
        return false;
    }
    if (c.header.color_type == 3 && c.palette_entries == 0) {
        error = "a palette image without a PLTE chunk";
        return false;
    }
    return true;
}

// Inflates the IDAT pieces into `raw` (its size is exactly the filtered image). Data after the
// image is ignored, as libpng does.
bool inflate_idat(const Chunks& c, std::vector<uint8_t>& raw, std::string& error) {
    z_stream z{};
    if (inflateInit(&z) != Z_OK) {
        error = "cannot start zlib";
        return false;
    }
    size_t produced = 0;
    bool ended = false;
    for (size_t i = 0; i < c.idat.size() && !ended && produced < raw.size(); ++i) {
        z.next_in = const_cast<Bytef*>(c.idat[i].first);
        z.avail_in = c.idat[i].second;
        while (z.avail_in > 0 && produced < raw.size()) {
            // avail_out is 32-bit: hand out the buffer in pieces.
            const size_t piece = std::min<size_t>(raw.size() - produced, size_t(1) << 30);
            z.next_out = raw.data() + produced;
            z.avail_out = uInt(piece);
            const int r = inflate(&z, Z_NO_FLUSH);
            produced += piece - z.avail_out;
            if (r == Z_STREAM_END) {
                ended = true;
                break;
            }
            if (r != Z_OK && r != Z_BUF_ERROR) {
                error = std::string("bad compressed image data (") +
                        (z.msg ? z.msg : "zlib error") + ")";
                inflateEnd(&z);
                return false;
            }
            if (r == Z_BUF_ERROR && z.avail_in > 0 && z.avail_out > 0) {
                error = "bad compressed image data (no progress)";
                inflateEnd(&z);
                return false;
            }
        }
    }
    inflateEnd(&z);
    if (produced < raw.size()) {
        error = "the image data is truncated (" + std::to_string(produced) + " of " +
                std::to_string(raw.size()) + " bytes)";
        return false;
    }
    return true;
}

uint8_t paeth(int a, int b, int c) {
    const int p = a + b - c;
    const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
    if (pa <= pb && pa <= pc) return uint8_t(a);
    if (pb <= pc) return uint8_t(b);
    return uint8_t(c);
}

// Undoes the five filters in place; each row is a filter byte then `row_bytes` bytes.
bool unfilter(std::vector<uint8_t>& raw, size_t rows, size_t row_bytes, size_t bpp,
              std::string& error) {
    const uint8_t* prev = nullptr;
    for (size_t y = 0; y < rows; ++y) {
        uint8_t* row = raw.data() + y * (row_bytes + 1);
        const int filter = row[0];
        uint8_t* cur = row + 1;
        switch (filter) {
            case 0:
                break;
            case 1:
                for (size_t i = bpp; i < row_bytes; ++i) cur[i] = uint8_t(cur[i] + cur[i - bpp]);
                break;
            case 2:
                if (prev)
                    for (size_t i = 0; i < row_bytes; ++i) cur[i] = uint8_t(cur[i] + prev[i]);
                break;
            case 3:
                for (size_t i = 0; i < row_bytes; ++i) {
                    const int left = i >= bpp ? cur[i - bpp] : 0;
                    const int up = prev ? prev[i] : 0;
                    cur[i] = uint8_t(cur[i] + ((left + up) >> 1));
                }
                break;
            case 4:
                for (size_t i = 0; i < row_bytes; ++i) {
                    const int left = i >= bpp ? cur[i - bpp] : 0;
                    const int up = prev ? prev[i] : 0;
                    const int up_left = (prev && i >= bpp) ? prev[i - bpp] : 0;
                    cur[i] = uint8_t(cur[i] + paeth(left, up, up_left));
                }
                break;
            default:
                error =
                    "bad filter type " + std::to_string(filter) + " in row " + std::to_string(y);
                return false;
        }
        prev = cur;
    }
    return true;
}

// Filtered rows -> float samples in the layout documented in png.h.
void expand(const Chunks& c, const std::vector<uint8_t>& raw, size_t row_bytes, PngPixels& out) {
    const Header& h = c.header;
    const int depth = h.bit_depth;
    int channels = h.file_channels;
    if (h.color_type == 3) channels = 3;
    if (c.has_trns && (h.color_type == 0 || h.color_type == 2 || h.color_type == 3)) ++channels;
    out.width = int(h.width);
    out.height = int(h.height);
    out.channels = channels;
    out.bit_depth = depth == 16 ? 16 : 8;
    out.samples.assign(size_t(h.width) * h.height * size_t(channels), 0.0f);

    std::array<float, 256> code8{};
    for (int k = 0; k < 256; ++k) code8[k] = float(k) / 255.0f;
    const float max16 = 65535.0f;
    const int low_max = (1 << depth) - 1;  // largest stored value for depths below 8

    for (uint32_t y = 0; y < h.height; ++y) {
        const uint8_t* row = raw.data() + size_t(y) * (row_bytes + 1) + 1;
        float* dst = out.samples.data() + size_t(y) * h.width * size_t(channels);
        for (uint32_t x = 0; x < h.width; ++x, dst += channels) {
            if (depth < 8) {
                const size_t bit = size_t(x) * depth;
                const int v = (row[bit >> 3] >> (8 - depth - int(bit & 7))) & low_max;
                if (h.color_type == 3) {
                    // libpng pads the palette to 256 entries with black.
                    const bool in = v < c.palette_entries;
                    for (int i = 0; i < 3; ++i) dst[i] = in ? code8[c.palette[3 * v + i]] : 0.0f;
                    if (c.has_trns) dst[3] = code8[c.palette_alpha[v]];
                } else {
                    dst[0] = code8[v * (255 / low_max)];
                    if (c.has_trns) dst[1] = v == (c.trns_key[0] & low_max) ? 0.0f : 1.0f;
                }
                continue;
            }
            if (h.color_type == 3) {
                const int v = row[x];
                const bool in = v < c.palette_entries;
                for (int i = 0; i < 3; ++i) dst[i] = in ? code8[c.palette[3 * v + i]] : 0.0f;
                if (c.has_trns) dst[3] = code8[c.palette_alpha[v]];
                continue;
            }
            const int n = h.file_channels;
            uint16_t v[4];
            if (depth == 16) {
                const uint8_t* p = row + size_t(x) * n * 2;
                for (int i = 0; i < n; ++i) v[i] = uint16_t(p[2 * i] << 8 | p[2 * i + 1]);
                for (int i = 0; i < n; ++i) dst[i] = float(v[i]) / max16;
            } else {
                const uint8_t* p = row + size_t(x) * n;
                for (int i = 0; i < n; ++i) v[i] = p[i];
                for (int i = 0; i < n; ++i) dst[i] = code8[v[i]];
            }
            if (c.has_trns && (h.color_type == 0 || h.color_type == 2)) {
                bool key = true;
                for (int i = 0; i < n; ++i) key = key && v[i] == c.trns_key[i];
                dst[n] = key ? 0.0f : 1.0f;
            }
        }
    }
}

struct FileCloser {
    void operator()(FILE* f) const {
        if (f) std::fclose(f);
    }
};
using File = std::unique_ptr<FILE, FileCloser>;

}  // namespace

PngStatus decode_png(const uint8_t* data, size_t size, size_t max_pixels, PngPixels& pixels,
                     std::string& error) {
    if (size < 8 || std::memcmp(data, kSignature, 8) != 0) return PngStatus::kNotPng;
    Chunks c;
    if (!parse_chunks(data, size, max_pixels, c, error)) return PngStatus::kError;
    const Header& h = c.header;
    if (h.interlaced) return PngStatus::kInterlaced;

    const uint64_t row_bytes = (uint64_t(h.width) * h.file_channels * h.bit_depth + 7) / 8;
    // A claimed 2^31 x 2^31 image overflows 64 bits here (the first test catches that); the ratio
    // test bounds what is allocated by the file's own size.
    const uint64_t raw_size = uint64_t(h.height) * (row_bytes + 1);
    if (row_bytes + 1 > UINT64_MAX / h.height ||
        c.idat_bytes * kMaxInflateRatio + kInflateSlack < raw_size) {
        error = "the image data (" + std::to_string(c.idat_bytes) + " bytes) is too short for a " +
                std::to_string(h.width) + " x " + std::to_string(h.height) + " image";
        return PngStatus::kError;
    }
    std::vector<uint8_t> raw(raw_size);
    if (!inflate_idat(c, raw, error)) return PngStatus::kError;
    const size_t bpp = std::max<size_t>(1, size_t(h.file_channels) * h.bit_depth / 8);
    if (!unfilter(raw, h.height, row_bytes, bpp, error)) return PngStatus::kError;
    expand(c, raw, row_bytes, pixels);
    return PngStatus::kOk;
}

PngStatus read_png(const std::string& path, size_t max_pixels, PngPixels& pixels,
                   std::string& error) {
    File f(std::fopen(path.c_str(), "rb"));
    if (!f) {
        error = std::strerror(errno);
        return PngStatus::kError;
    }
    // Signature and IHDR first: a too large image is refused before the file is read.
    uint8_t head[33];
    const size_t got = std::fread(head, 1, sizeof head, f.get());
    if (got < 8 || std::memcmp(head, kSignature, 8) != 0) return PngStatus::kNotPng;
    if (got == sizeof head && std::memcmp(head + 12, "IHDR", 4) == 0) {
        Header h;
        if (!parse_ihdr(head + 16, be32(head + 8), max_pixels, h, error)) return PngStatus::kError;
    }
    if (std::fseek(f.get(), 0, SEEK_END) != 0) {
        error = std::strerror(errno);
        return PngStatus::kError;
    }
    const long size = std::ftell(f.get());
    if (size < 0 || std::fseek(f.get(), 0, SEEK_SET) != 0) {
        error = "cannot find the file's size";
        return PngStatus::kError;
    }
    std::vector<uint8_t> bytes(static_cast<size_t>(size));
    if (std::fread(bytes.data(), 1, bytes.size(), f.get()) != bytes.size()) {
        error = "cannot read the file";
        return PngStatus::kError;
    }
    return decode_png(bytes.data(), bytes.size(), max_pixels, pixels, error);
}

namespace {

// Writes chunks and deflates the image data into IDAT chunks as it goes.
struct PngWriter {
    FILE* file = nullptr;
    bool ok = true;

    void put(const void* data, size_t n) {
        if (ok && n > 0 && std::fwrite(data, 1, n, file) != n) ok = false;
    }
    void chunk(const char* type, const uint8_t* data, size_t length) {
        uint8_t head[8];
        const uint32_t len = uint32_t(length);
        head[0] = uint8_t(len >> 24), head[1] = uint8_t(len >> 16);
        head[2] = uint8_t(len >> 8), head[3] = uint8_t(len);
        std::memcpy(head + 4, type, 4);
        uLong crc = crc32(0L, head + 4, 4);
        if (length > 0) crc = crc32(crc, data, uInt(length));
        uint8_t tail[4] = {uint8_t(crc >> 24), uint8_t(crc >> 16), uint8_t(crc >> 8), uint8_t(crc)};
        put(head, 8);
        put(data, length);
        put(tail, 4);
    }
};

void put32(uint8_t* p, uint32_t v) {
    p[0] = uint8_t(v >> 24), p[1] = uint8_t(v >> 16), p[2] = uint8_t(v >> 8), p[3] = uint8_t(v);
}

// Sum of the filtered bytes taken as signed values' magnitudes: libpng's choice of filter.
uint64_t filter_cost(const uint8_t* f, size_t n) {
    uint64_t sum = 0;
    for (size_t i = 0; i < n; ++i) sum += f[i] < 128 ? f[i] : 256 - f[i];
    return sum;
}

// Filters `cur` (previous row `prev`, or null for the first) by every filter and returns the
// cheapest, filter byte first. One loop per filter keeps the inner loops branch-free.
const std::vector<uint8_t>& filter_row(const uint8_t* cur, const uint8_t* prev, size_t n,
                                       size_t bpp, std::vector<uint8_t> (&trial)[5]) {
    std::vector<uint8_t> zero_row;
    if (!prev) {
        zero_row.assign(n, 0);
        prev = zero_row.data();
    }
    for (int ft = 0; ft < 5; ++ft) trial[ft][0] = uint8_t(ft);
    uint8_t* none = trial[0].data() + 1;
    uint8_t* sub = trial[1].data() + 1;
    uint8_t* up = trial[2].data() + 1;
    uint8_t* avg = trial[3].data() + 1;
    uint8_t* pae = trial[4].data() + 1;
    std::memcpy(none, cur, n);
    for (size_t i = 0; i < std::min(bpp, n); ++i) {
        sub[i] = cur[i];
        up[i] = uint8_t(cur[i] - prev[i]);
        avg[i] = uint8_t(cur[i] - (prev[i] >> 1));
        pae[i] = uint8_t(cur[i] - prev[i]);  // Paeth with left = up-left = 0 predicts up
    }
    for (size_t i = bpp; i < n; ++i) {
        sub[i] = uint8_t(cur[i] - cur[i - bpp]);
        up[i] = uint8_t(cur[i] - prev[i]);
        avg[i] = uint8_t(cur[i] - ((cur[i - bpp] + prev[i]) >> 1));
        pae[i] = uint8_t(cur[i] - paeth(cur[i - bpp], prev[i], prev[i - bpp]));
    }
    int best = 0;
    uint64_t best_cost = UINT64_MAX;
    for (int ft = 0; ft < 5; ++ft) {
        const uint64_t cost = filter_cost(trial[ft].data() + 1, n);
        if (cost < best_cost) best_cost = cost, best = ft;
    }
    return trial[best];
}

}  // namespace

bool write_png(const std::string& path, int width, int height, int channels, int bit_depth,
               const void* samples, bool srgb, std::string& error) {
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4 ||
        (bit_depth != 8 && bit_depth != 16)) {
        error = "bad image layout for PNG";
        return false;
    }
    static constexpr uint8_t kColorType[5] = {0, 0, 4, 2, 6};
    const size_t bpp = size_t(channels) * size_t(bit_depth / 8);
    const size_t row_bytes = size_t(width) * bpp;

    File f(std::fopen(path.c_str(), "wb"));
    if (!f) {
        error = std::strerror(errno);
        return false;
    }
    PngWriter w;
    w.file = f.get();
    w.put(kSignature, 8);
    uint8_t ihdr[13];
    put32(ihdr, uint32_t(width));
    put32(ihdr + 4, uint32_t(height));
    ihdr[8] = uint8_t(bit_depth), ihdr[9] = kColorType[channels];
    ihdr[10] = ihdr[11] = ihdr[12] = 0;
    w.chunk("IHDR", ihdr, 13);
    if (srgb) {
        // What libpng's png_set_sRGB_gAMA_and_cHRM writes (OpenImageIO's choice for sRGB).
        uint8_t gama[4];
        put32(gama, 45455);
        w.chunk("gAMA", gama, 4);
        const uint8_t intent = 3;
        w.chunk("sRGB", &intent, 1);
        static constexpr uint32_t kChrm[8] = {31270, 32900, 64000, 33000,
                                              30000, 60000, 15000, 6000};
        uint8_t chrm[32];
        for (int i = 0; i < 8; ++i) put32(chrm + 4 * i, kChrm[i]);
        w.chunk("cHRM", chrm, 32);
    }
    static constexpr char kSoftware[] = "Software\0vrmlray";
    w.chunk("tEXt", reinterpret_cast<const uint8_t*>(kSoftware), sizeof kSoftware - 1);

    z_stream z{};
    if (deflateInit2(&z, 6, Z_DEFLATED, 15, 8, Z_FILTERED) != Z_OK) {
        error = "cannot start zlib";
        return false;
    }
    std::vector<uint8_t> out(size_t(1) << 16);
    auto drain = [&](int flush) {
        int r = Z_OK;
        do {
            z.next_out = out.data();
            z.avail_out = uInt(out.size());
            r = deflate(&z, flush);
            const size_t n = out.size() - z.avail_out;
            if (n > 0) w.chunk("IDAT", out.data(), n);
        } while (z.avail_out == 0 || (flush == Z_FINISH && r == Z_OK));
        return r;
    };

    // Rows in stored byte order (16-bit big-endian), this one and the previous.
    std::vector<uint8_t> rows[2] = {std::vector<uint8_t>(row_bytes),
                                    std::vector<uint8_t>(row_bytes)};
    std::vector<uint8_t> trial[5];
    for (auto& t : trial) t.resize(row_bytes + 1);
    for (int y = 0; y < height && w.ok; ++y) {
        std::vector<uint8_t>& cur = rows[y & 1];
        const size_t n = size_t(width) * size_t(channels);
        if (bit_depth == 8) {
            std::memcpy(cur.data(), static_cast<const uint8_t*>(samples) + size_t(y) * n, n);
        } else {
            const uint16_t* src = static_cast<const uint16_t*>(samples) + size_t(y) * n;
            for (size_t i = 0; i < n; ++i) {
                cur[2 * i] = uint8_t(src[i] >> 8);
                cur[2 * i + 1] = uint8_t(src[i]);
            }
        }
        const std::vector<uint8_t>& best = filter_row(
            cur.data(), y > 0 ? rows[(y - 1) & 1].data() : nullptr, row_bytes, bpp, trial);
        z.next_in = const_cast<Bytef*>(best.data());
        z.avail_in = uInt(best.size());
        drain(Z_NO_FLUSH);
    }
    const int r = w.ok ? drain(Z_FINISH) : Z_OK;
    deflateEnd(&z);
    if (r != Z_STREAM_END && w.ok) {
        error = "zlib could not compress the image";
        w.ok = false;
    }
    if (w.ok) w.chunk("IEND", nullptr, 0);
    if (!w.ok) {
        error = error.empty() ? std::string("write error: ") + std::strerror(errno) : error;
        f.reset();
        std::remove(path.c_str());
        return false;
    }
    if (std::fclose(f.release()) != 0) {
        error = std::string("write error: ") + std::strerror(errno);
        std::remove(path.c_str());
        return false;
    }
    return true;
}

}  // namespace vr
