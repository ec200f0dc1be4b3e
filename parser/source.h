// Source files held in memory, and byte offsets turned into line and column only when a message is
// printed.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace vr {

// A byte offset into a source file's text. 64 bits: a molecule export of 10^8 atoms is some
// 29 GB (issue 45), and offsets only become lines and columns when a message is printed.
using SourceOffset = uint64_t;

// A place in a source file: the file's index in a SourceManager and a byte offset into its text.
struct SourceLoc {
    uint32_t file =
        UINT32_MAX;  // UINT32_MAX: no place (e.g. a value that came from a grammar default)
    SourceOffset offset = 0;
    bool valid() const { return file != UINT32_MAX; }
};

// A SourceLoc in 7 bytes with no alignment, for the node tree's millions of nodes and field entries
// (and the typed scene's origins): an 18-bit file index, which SourceManager::add guarantees
// (kMaxFiles), and a 38-bit offset, which the loader guarantees (kMaxSourceBytes: 256 GiB, some
// 900 million atoms of a PyMOL-style export). The two share the 56 bits so that a node stays at
// 20 bytes.
struct PackedLoc {
    static constexpr int kFileBits = 18;
    static constexpr int kOffsetBits = 56 - kFileBits;
    static constexpr uint32_t kNoFile = (uint32_t(1) << kFileBits) - 1;  // SourceLoc's UINT32_MAX
    static constexpr SourceOffset kMaxOffset = (SourceOffset(1) << kOffsetBits) - 1;

    uint8_t bytes[7] = {0xff, 0xff, 0x03, 0, 0, 0, 0};  // file, then offset; little-endian
    PackedLoc() = default;
    PackedLoc(uint32_t file, SourceOffset offset) : PackedLoc(SourceLoc{file, offset}) {}
    PackedLoc(SourceLoc loc) {
        const uint64_t f = loc.valid() ? loc.file : kNoFile;
        const uint64_t v = (f & kNoFile) | ((loc.offset & kMaxOffset) << kFileBits);
        for (int i = 0; i < 7; ++i) bytes[i] = static_cast<uint8_t>(v >> (8 * i));
    }
    operator SourceLoc() const { return get(); }
    SourceLoc get() const {
        uint64_t v = 0;
        for (int i = 0; i < 7; ++i) v |= uint64_t(bytes[i]) << (8 * i);
        const auto f = static_cast<uint32_t>(v & kNoFile);
        return {f == kNoFile ? UINT32_MAX : f, v >> kFileBits};
    }
    bool valid() const { return get().valid(); }
};

// The most bytes a source file may have: the offsets a PackedLoc holds.
inline constexpr SourceOffset kMaxSourceBytes = PackedLoc::kMaxOffset + 1;

struct LineCol {
    uint64_t line = 0;    // 1-based
    uint64_t column = 0;  // 1-based, in bytes
};

// The bytes of one file: owned in memory (decompressed gzip, text given by a caller), or mapped
// read-only from the file itself. A mapped file costs no copy, and the pages a reader has passed
// can be handed back to the kernel (they stay in its page cache and come back, unchanged, when
// touched again), so a large plain-text scene does not hold its text in the process's memory while
// the node tree grows.
class SourceText {
  public:
    SourceText() = default;
    explicit SourceText(std::string text);
    // Maps `size` bytes of the open file `fd` (not closed here). Returns an empty text when mapping
    // fails.
    static SourceText map(int fd, size_t size);
    SourceText(SourceText&& other) noexcept;
    SourceText& operator=(SourceText&& other) noexcept;
    SourceText(const SourceText&) = delete;
    SourceText& operator=(const SourceText&) = delete;
    ~SourceText();

    std::string_view view() const {
        return mapped_ ? std::string_view(mapped_, mapped_size_) : owned_;
    }
    bool mapped() const { return mapped_ != nullptr; }
    // Mapped text: lets the kernel take back the whole pages in [begin, end). Contents never
    // change.
    void release(size_t begin, size_t end) const;

  private:
    std::string owned_;
    const char* mapped_ = nullptr;
    size_t mapped_size_ = 0;
};

struct SourceFile {
    std::string path;  // as the user or the including file named it, resolved to a usable path
    SourceText storage;
    std::string_view text;  // decompressed bytes (a view of storage)
    // Newlines before every kLineBlock-th byte, computed on first use: line numbers for messages
    // come from counting within one block, so a message in a huge file costs neither a full line
    // index nor its text.
    static constexpr uint32_t kLineBlock = 1 << 16;
    mutable std::vector<uint64_t> lines_before_block;
    mutable uint64_t released_to =
        0;  // mapped text: bytes below this were given back by release_before
};

class SourceManager {
  public:
    // Files one scene may read (main file, Inlines, EXTERNPROTO files): indices fit PackedLoc.
    static constexpr uint32_t kMaxFiles = PackedLoc::kNoFile;
    // Throws std::length_error past kMaxFiles files.
    uint32_t add(std::string path, std::string text);
    uint32_t add(std::string path, SourceText text);
    const SourceFile& file(uint32_t index) const { return *files_.at(index); }
    uint32_t size() const { return static_cast<uint32_t>(files_.size()); }
    LineCol line_col(SourceLoc loc) const;
    // The text of the given 1-based line, without its line break.
    std::string_view line_text(uint32_t file, uint64_t line) const;
    // The text of the line that holds `loc`, without its line break.
    std::string_view line_text(SourceLoc loc) const;
    // A reader of a mapped file has passed `offset`: gives back the pages before it, a few
    // megabytes at a time. Nothing changes for anyone reading them again; it only keeps them out of
    // the process's memory.
    void release_before(uint32_t file, SourceOffset offset) const;
    // A reader is done with the whole file: gives back all of its pages at once.
    void release_all(uint32_t file) const;
    // Moves a file's bytes out, to be read again elsewhere; this manager is not used afterwards.
    SourceText take_text(uint32_t index) { return std::move(files_.at(index)->storage); }

  private:
    std::vector<std::unique_ptr<SourceFile>> files_;  // pointers stay valid while files are added
};

}  // namespace vr
