#include "parser/source.h"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "parser/utf16.h"

namespace vr {

SourceText::SourceText(std::string text) : owned_(std::move(text)) {}

SourceText SourceText::map(int fd, size_t size) {
    SourceText t;
    if (size == 0) return t;
    void* p = mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED) return t;
    madvise(p, size, MADV_SEQUENTIAL);  // read ahead: readers go from the first byte to the last
    t.mapped_ = static_cast<const char*>(p);
    t.mapped_size_ = size;
    return t;
}

SourceText::SourceText(SourceText&& other) noexcept
    : owned_(std::move(other.owned_)), mapped_(other.mapped_), mapped_size_(other.mapped_size_) {
    other.mapped_ = nullptr;
    other.mapped_size_ = 0;
}

SourceText& SourceText::operator=(SourceText&& other) noexcept {
    if (this != &other) {
        if (mapped_) munmap(const_cast<char*>(mapped_), mapped_size_);
        owned_ = std::move(other.owned_);
        mapped_ = other.mapped_;
        mapped_size_ = other.mapped_size_;
        other.mapped_ = nullptr;
        other.mapped_size_ = 0;
    }
    return *this;
}

SourceText::~SourceText() {
    if (mapped_) munmap(const_cast<char*>(mapped_), mapped_size_);
}

void SourceText::release(size_t begin, size_t end) const {
    if (!mapped_) return;
    static const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
    end = std::min(end, mapped_size_);
    begin = (begin + page - 1) / page * page;  // whole pages only
    end = end / page * page;
    // The mapping is private and never written, so its pages come back from the file as they were.
    if (end > begin) madvise(const_cast<char*>(mapped_) + begin, end - begin, MADV_DONTNEED);
}

uint32_t SourceManager::add(std::string path, std::string text) {
    return add(std::move(path), SourceText(std::move(text)));
}

uint32_t SourceManager::add(std::string path, SourceText text) {
    if (files_.size() >= kMaxFiles)
        throw std::length_error("more than " + std::to_string(kMaxFiles) + " source files (limit)");
    auto file = std::make_unique<SourceFile>();
    file->path = std::move(path);
    // UTF-16 with a byte-order mark: every reader reads UTF-8 (parser/utf16.h).
    if (std::optional<std::string> utf8 = utf8_from_utf16(text.view()))
        text = SourceText(std::move(*utf8));
    file->storage = std::move(text);
    file->text =
        file->storage.view();  // after the move: a short owned string lives inside the storage
    files_.push_back(std::move(file));
    return static_cast<uint32_t>(files_.size() - 1);
}

void SourceManager::release_before(uint32_t file, SourceOffset offset) const {
    constexpr uint64_t kStep = uint64_t(4) << 20;
    if (file >= files_.size()) return;
    const SourceFile& f = *files_[file];
    if (!f.storage.mapped() || offset < f.released_to + kStep) return;
    f.storage.release(f.released_to, offset);
    f.released_to = offset;
}

void SourceManager::release_all(uint32_t file) const {
    if (file >= files_.size()) return;
    const SourceFile& f = *files_[file];
    if (!f.storage.mapped()) return;
    f.storage.release(f.released_to, f.text.size());
    f.released_to = f.text.size();
}

namespace {

// Counts newlines of whole blocks until block `block` (or the end of the text) has its entry.
void index_blocks(const SourceFile& f, size_t block) {
    auto& counts = f.lines_before_block;
    if (counts.empty()) counts.push_back(0);
    const size_t first_new = counts.size();
    while (counts.size() <= block) {
        const size_t begin = (counts.size() - 1) * size_t(SourceFile::kLineBlock);
        if (begin >= f.text.size()) break;
        const size_t end = std::min(f.text.size(), begin + SourceFile::kLineBlock);
        counts.push_back(counts.back() + static_cast<uint64_t>(std::count(
                                             f.text.data() + begin, f.text.data() + end, '\n')));
    }
    // Pages a reader had already given back go back again.
    if (counts.size() > first_new) {
        const size_t begin = (first_new - 1) * size_t(SourceFile::kLineBlock);
        const size_t end =
            std::min<size_t>((counts.size() - 1) * size_t(SourceFile::kLineBlock), f.released_to);
        if (end > begin) f.storage.release(begin, end);
    }
}

}  // namespace

LineCol SourceManager::line_col(SourceLoc loc) const {
    if (!loc.valid() || loc.file >= files_.size()) return {};
    const SourceFile& f = *files_[loc.file];
    const size_t offset = std::min<size_t>(loc.offset, f.text.size());
    const size_t block = offset / SourceFile::kLineBlock;
    index_blocks(f, block);
    const size_t block_begin = block * size_t(SourceFile::kLineBlock);
    const char* s = f.text.data();
    const uint64_t newlines = f.lines_before_block[block] +
                              static_cast<uint64_t>(std::count(s + block_begin, s + offset, '\n'));
    size_t line_start = offset;
    while (line_start > 0 && s[line_start - 1] != '\n') --line_start;
    return {newlines + 1, uint64_t(offset - line_start + 1)};
}

static std::string_view line_from(std::string_view text, size_t start) {
    size_t end = text.find('\n', start);
    std::string_view line =
        text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start);
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
    return line;
}

std::string_view SourceManager::line_text(uint32_t file, uint64_t line) const {
    if (file >= files_.size() || line == 0) return {};
    const SourceFile& f = *files_[file];
    const uint64_t wanted = line - 1;  // newlines before the line
    auto& counts = f.lines_before_block;
    size_t pos = 0;
    if (wanted > 0) {
        // Index blocks until one starts after the wanted newline (or the text ends).
        while (counts.empty() ||
               (counts.back() < wanted &&
                (counts.size() - 1) * size_t(SourceFile::kLineBlock) < f.text.size())) {
            index_blocks(f, counts.empty() ? 0 : counts.size());
        }
        // The last block with fewer newlines before it holds the wanted newline, if the file has
        // it.
        size_t block = static_cast<size_t>(std::lower_bound(counts.begin(), counts.end(), wanted) -
                                           counts.begin()) -
                       1;
        pos = block * size_t(SourceFile::kLineBlock);
        for (uint64_t seen = counts[block]; seen < wanted; ++seen) {
            size_t nl = f.text.find('\n', pos);
            if (nl == std::string_view::npos) return {};  // the file has fewer lines
            pos = nl + 1;
        }
    }
    if (pos > f.text.size()) return {};
    return line_from(f.text, pos);
}

std::string_view SourceManager::line_text(SourceLoc loc) const {
    if (!loc.valid() || loc.file >= files_.size()) return {};
    const SourceFile& f = *files_[loc.file];
    size_t start = std::min<size_t>(loc.offset, f.text.size());
    while (start > 0 && f.text[start - 1] != '\n') --start;
    return line_from(f.text, start);
}

}  // namespace vr
