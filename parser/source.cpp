#include "parser/source.h"

#include <algorithm>

namespace vr {

uint32_t SourceManager::add(std::string path, std::string text) {
    auto file = std::make_unique<SourceFile>();
    file->path = std::move(path);
    file->text = std::move(text);
    files_.push_back(std::move(file));
    return static_cast<uint32_t>(files_.size() - 1);
}

static void index_lines(const SourceFile& f) {
    if (!f.line_starts.empty()) return;
    f.line_starts.push_back(0);
    for (size_t i = 0; i < f.text.size(); ++i) {
        if (f.text[i] == '\n') f.line_starts.push_back(static_cast<uint32_t>(i + 1));
    }
}

LineCol SourceManager::line_col(SourceLoc loc) const {
    if (!loc.valid() || loc.file >= files_.size()) return {};
    const SourceFile& f = *files_[loc.file];
    index_lines(f);
    auto it = std::upper_bound(f.line_starts.begin(), f.line_starts.end(), loc.offset);
    uint32_t line = static_cast<uint32_t>(it - f.line_starts.begin());  // 1-based
    uint32_t start = f.line_starts[line - 1];
    return {line, loc.offset - start + 1};
}

std::string_view SourceManager::line_text(uint32_t file, uint32_t line) const {
    if (file >= files_.size()) return {};
    const SourceFile& f = *files_[file];
    index_lines(f);
    if (line == 0 || line > f.line_starts.size()) return {};
    size_t start = f.line_starts[line - 1];
    size_t end = line < f.line_starts.size() ? f.line_starts[line] : f.text.size();
    std::string_view text(f.text.data() + start, end - start);
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.remove_suffix(1);
    return text;
}

}  // namespace vr
