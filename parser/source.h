// Source files held in memory, and byte offsets turned into line and column only when a message is
// printed.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace vr {

// A place in a source file: the file's index in a SourceManager and a byte offset into its text.
struct SourceLoc {
    uint32_t file =
        UINT32_MAX;  // UINT32_MAX: no place (e.g. a value that came from a grammar default)
    uint32_t offset = 0;
    bool valid() const { return file != UINT32_MAX; }
};

// A SourceLoc in 7 bytes with no alignment, for the node tree's millions of field entries: the file
// index has 24 bits, which SourceManager::add guarantees (kMaxFiles).
struct PackedLoc {
    uint8_t bytes[7] = {0xff, 0xff, 0xff, 0, 0, 0, 0};  // file (3), offset (4), little-endian
    PackedLoc() = default;
    PackedLoc(uint32_t file, uint32_t offset) : PackedLoc(SourceLoc{file, offset}) {}
    PackedLoc(SourceLoc loc) {
        const uint32_t f = loc.valid() ? loc.file : kNoFile;
        for (int i = 0; i < 3; ++i) bytes[i] = static_cast<uint8_t>(f >> (8 * i));
        for (int i = 0; i < 4; ++i) bytes[3 + i] = static_cast<uint8_t>(loc.offset >> (8 * i));
    }
    operator SourceLoc() const { return get(); }
    SourceLoc get() const {
        uint32_t f = 0, o = 0;
        for (int i = 0; i < 3; ++i) f |= uint32_t(bytes[i]) << (8 * i);
        for (int i = 0; i < 4; ++i) o |= uint32_t(bytes[3 + i]) << (8 * i);
        return {f == kNoFile ? UINT32_MAX : f, o};
    }
    bool valid() const { return get().valid(); }
    static constexpr uint32_t kNoFile = 0xffffff;  // no place (SourceLoc's UINT32_MAX)
};

struct LineCol {
    uint32_t line = 0;    // 1-based
    uint32_t column = 0;  // 1-based, in bytes
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
    mutable std::vector<uint32_t> lines_before_block;
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
    std::string_view line_text(uint32_t file, uint32_t line) const;
    // The text of the line that holds `loc`, without its line break.
    std::string_view line_text(SourceLoc loc) const;
    // A reader of a mapped file has passed `offset`: gives back the pages before it, a few
    // megabytes at a time. Nothing changes for anyone reading them again; it only keeps them out of
    // the process's memory.
    void release_before(uint32_t file, uint32_t offset) const;
    // A reader is done with the whole file: gives back all of its pages at once.
    void release_all(uint32_t file) const;
    // Moves a file's bytes out, to be read again elsewhere; this manager is not used afterwards.
    SourceText take_text(uint32_t index) { return std::move(files_.at(index)->storage); }

  private:
    std::vector<std::unique_ptr<SourceFile>> files_;  // pointers stay valid while files are added
};

}  // namespace vr
