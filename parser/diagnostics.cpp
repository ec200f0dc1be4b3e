#include "parser/diagnostics.h"

#include <algorithm>

namespace vr {

void Diagnostics::error(SourceLoc loc, std::string message) {
    items_.push_back({Severity::Error, loc, {}, std::move(message), 1});
    ++error_count_;
}

void Diagnostics::error_in_file(std::string file, std::string message) {
    items_.push_back({Severity::Error, {}, std::move(file), std::move(message), 1});
    ++error_count_;
}

void Diagnostics::warning(SourceLoc loc, std::string message, const std::string& cause) {
    auto it = warning_index_.find(cause);
    if (it != warning_index_.end()) {
        ++items_[it->second].count;
        return;
    }
    warning_index_.emplace(cause, items_.size());
    items_.push_back({Severity::Warning, loc, {}, std::move(message), 1});
}

void Diagnostics::warning_in_file(std::string file, std::string message, const std::string& cause) {
    auto it = warning_index_.find(cause);
    if (it != warning_index_.end()) {
        ++items_[it->second].count;
        return;
    }
    warning_index_.emplace(cause, items_.size());
    items_.push_back({Severity::Warning, {}, std::move(file), std::move(message), 1});
}

void Diagnostics::append(const Diagnostics& later) {
    std::vector<const std::string*> cause(later.items_.size(), nullptr);
    for (const auto& [text, index] : later.warning_index_) cause[index] = &text;
    for (size_t i = 0; i < later.items_.size(); ++i) {
        const Diagnostic& d = later.items_[i];
        if (cause[i]) {
            auto it = warning_index_.find(*cause[i]);
            if (it != warning_index_.end()) {
                items_[it->second].count += d.count;
                continue;
            }
            warning_index_.emplace(*cause[i], items_.size());
        }
        if (d.severity == Severity::Error) ++error_count_;
        items_.push_back(d);
    }
}

size_t Diagnostics::warning_count() const {
    return static_cast<size_t>(std::count_if(items_.begin(), items_.end(), [](const Diagnostic& d) {
        return d.severity == Severity::Warning;
    }));
}

std::string Diagnostics::format_one(const Diagnostic& d, const SourceManager& sources) {
    std::string out;
    const char* kind = d.severity == Severity::Error ? "error" : "warning";
    if (d.loc.valid() && d.loc.file < sources.size()) {
        LineCol lc = sources.line_col(d.loc);
        out += sources.file(d.loc.file).path + ":" + std::to_string(lc.line) + ":" +
               std::to_string(lc.column) + ": " + kind + ": " + d.message;
        if (d.count > 1) out += " (" + std::to_string(d.count) + " times)";
        out += "\n";
        std::string_view line = sources.line_text(d.loc);
        if (line.size() <= 300) {
            out += "  ";
            out += line;
            out += "\n  ";
            for (uint64_t i = 1; i < lc.column && i <= line.size(); ++i)
                out += line[i - 1] == '\t' ? '\t' : ' ';
            out += "^\n";
        }
    } else {
        out += (d.file.empty() ? std::string("vrmlray") : d.file) + ": " + kind + ": " + d.message;
        if (d.count > 1) out += " (" + std::to_string(d.count) + " times)";
        out += "\n";
    }
    return out;
}

std::string Diagnostics::format(const SourceManager& sources) const {
    std::string out;
    for (const Diagnostic& d : items_) out += format_one(d, sources);
    return out;
}

}  // namespace vr
