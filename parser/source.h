// Source files held in memory, and byte offsets turned into line and column only when a message is printed.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace vr {

// A place in a source file: the file's index in a SourceManager and a byte offset into its text.
struct SourceLoc {
    uint32_t file = UINT32_MAX;  // UINT32_MAX: no place (e.g. a value that came from a grammar default)
    uint32_t offset = 0;
    bool valid() const { return file != UINT32_MAX; }
};

struct LineCol {
    uint32_t line = 0;    // 1-based
    uint32_t column = 0;  // 1-based, in bytes
};

struct SourceFile {
    std::string path;  // as the user or the including file named it, resolved to a usable path
    std::string text;  // decompressed bytes
    mutable std::vector<uint32_t> line_starts;  // computed on first use
};

class SourceManager {
public:
    uint32_t add(std::string path, std::string text);
    const SourceFile& file(uint32_t index) const { return *files_.at(index); }
    uint32_t size() const { return static_cast<uint32_t>(files_.size()); }
    LineCol line_col(SourceLoc loc) const;
    // The text of the given 1-based line, without its line break.
    std::string_view line_text(uint32_t file, uint32_t line) const;

private:
    std::vector<std::unique_ptr<SourceFile>> files_;  // pointers stay valid while files are added
};

}  // namespace vr
