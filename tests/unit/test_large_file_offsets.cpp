// Places past 4 GiB (issue 45: a 10^8-atom PyMOL-style export is some 29 GB). With 32-bit offsets a
// piece that began past 4 GiB was read from its offset modulo 2^32, so the 29 GB file failed at a
// wrong line. Reading a real 4 GiB file costs CI too much (bench/README.md, "Issue 45: files over
// 4 GiB", reads one), so these tests give the readers a text of 4 GiB and a little more whose
// first 4 GiB are never touched: an anonymous mapping reserved without memory, only its last pages
// written. A reader that truncates an offset reads those untouched zero bytes instead of the text.
#include <gtest/gtest.h>
#include <sys/mman.h>

#include <cstring>
#include <string>
#include <string_view>

#include "parser/lexer.h"
#include "parser/source.h"
#include "scene/plain_piece.h"

namespace vr {
namespace {

constexpr size_t kFourGiB = size_t(1) << 32;

// A read-write text of `size` bytes, zero but for what is written into it; its untouched pages
// take no memory.
class SparseText {
  public:
    explicit SparseText(size_t size) : size_(size) {
        void* p = mmap(nullptr, size, PROT_READ | PROT_WRITE,
                       MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
        data_ = p == MAP_FAILED ? nullptr : static_cast<char*>(p);
    }
    ~SparseText() {
        if (data_) munmap(data_, size_);
    }
    SparseText(const SparseText&) = delete;
    SparseText& operator=(const SparseText&) = delete;
    bool ok() const { return data_ != nullptr; }
    void write(size_t at, std::string_view bytes) {
        std::memcpy(data_ + at, bytes.data(), bytes.size());
    }
    std::string_view view() const { return {data_, size_}; }

  private:
    char* data_ = nullptr;
    size_t size_ = 0;
};

TEST(LargeFileOffsets, LexerReadsTokensPastFourGiB) {
    SparseText text(kFourGiB + 8192);
    ASSERT_TRUE(text.ok());
    const size_t at = kFourGiB + 100;
    text.write(at, "Sphere { radius 2.5 } # end\n\"a string\"");
    Lexer lexer(text.view(), at, text.view().size());
    const Token sphere = lexer.next();
    EXPECT_EQ(sphere.kind, TokenKind::Word);
    EXPECT_EQ(sphere.offset, at);
    EXPECT_EQ(lexer.text(sphere), "Sphere");
    EXPECT_EQ(lexer.next().kind, TokenKind::LBrace);
    EXPECT_EQ(lexer.text(lexer.next()), "radius");
    Decimal d;
    const Token radius = lexer.next_number(d);
    EXPECT_EQ(radius.offset, at + 16);
    double value = 0.0;
    ASSERT_TRUE(d.plain && d.to_double(value));
    EXPECT_EQ(value, 2.5);
    EXPECT_EQ(lexer.next().kind, TokenKind::RBrace);
    const Token string = lexer.next();  // after the comment and its line break
    EXPECT_EQ(string.kind, TokenKind::String);
    EXPECT_EQ(string.offset, at + 28);
    EXPECT_EQ(lexer.text(string), "\"a string\"");
    EXPECT_GT(lexer.position(), kFourGiB);
}

// The node tree's and the typed scene's places stay 7 bytes: at 10^8 atoms a byte a node is
// 500 MB.
TEST(LargeFileOffsets, PackedPlacesKeepOffsetsPastFourGiB) {
    // 256 GiB - 1: the last offset a place holds (a 38-bit offset beside an 18-bit file index).
    for (uint64_t offset :
         {uint64_t(kFourGiB), uint64_t(29'000'000'000), (uint64_t(1) << 38) - 1}) {
        for (uint32_t file : {0u, 7u, (1u << 18) - 2}) {
            SourceLoc loc;
            loc.file = file;
            loc.offset = offset;
            const SourceLoc back = PackedLoc(loc);
            EXPECT_EQ(back.file, file);
            EXPECT_EQ(back.offset, offset);
        }
    }
    // The loader reads a file up to the offsets a place holds (parser/load.cpp), and --limit
    // file-bytes goes no higher (src/app/limits.cpp).
    EXPECT_EQ(kMaxSourceBytes, uint64_t(1) << 38);
    EXPECT_EQ(PackedLoc::kMaxOffset, (uint64_t(1) << 38) - 1);
    EXPECT_EQ(SourceManager::kMaxFiles, (1u << 18) - 1);
    EXPECT_EQ(sizeof(PackedLoc), 7u);
    EXPECT_EQ(sizeof(sg::Origin), 16u);
}

// A plain piece (scene/plain_piece.h) of the 10^8-atom export, cut past 4 GiB: every node is read
// from its own bytes and its origin (which messages about it print) is its own place.
TEST(LargeFileOffsets, PlainPiecePastFourGiBHasItsOwnPlaces) {
    SparseText text(kFourGiB + (size_t(1) << 20));
    ASSERT_TRUE(text.ok());
    // Two atoms of the same length whose spheres differ (equal ones would share one geometry).
    auto atom = [](char digit) {
        return std::string(
                   "Transform { translation 1 2 3 children Shape {\n"
                   "  appearance Appearance { material Material { diffuseColor 0.2 0.4 0.6 "
                   "} }\n  geometry Sphere { radius 0.7") +
               digit + " } } }\n";
    };
    const size_t size = atom('5').size();
    const size_t begin = kFourGiB + 4096;  // a line start, as the piece reader cuts
    text.write(begin - 1, "\n");
    text.write(begin, atom('5'));
    text.write(begin + size, atom('6'));
    PieceText piece;
    piece.source = text.view();
    piece.file = 3;
    piece.begin = begin;
    piece.end = begin + 2 * size;
    piece.max_nodes = 1000;
    piece.max_depth = 100;
    piece.max_values = 1000;
    const std::optional<PlainPiece> plain = read_plain_piece(piece);
    ASSERT_TRUE(plain.has_value());
    const Scene& s = plain->fragment;
    ASSERT_EQ(s.geometries.size(), 2u);
    EXPECT_EQ(plain->counts.roots, 2u);
    for (size_t k = 0; k < 2; ++k) {
        const SourceLoc loc = s.geometries[k].origin.loc;
        EXPECT_EQ(loc.file, 3u);
        EXPECT_EQ(loc.offset, begin + k * size + atom('5').find("Sphere")) << k;
    }
    const auto& first = std::get<sg::Sphere>(s.geometries[0].shape);
    const auto& second = std::get<sg::Sphere>(s.geometries[1].shape);
    EXPECT_EQ(first.radius, 0.75);  // the atoms' own values, not zero bytes
    EXPECT_EQ(second.radius, 0.76);
}

}  // namespace
}  // namespace vr
