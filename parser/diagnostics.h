// Errors and warnings collected while reading; the command line decides what to print and the exit
// code.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "parser/source.h"

namespace vr {

enum class Severity : uint8_t { Warning, Error };

struct Diagnostic {
    Severity severity = Severity::Error;
    SourceLoc loc;  // may be invalid (no place in a file)
    std::string
        file;  // used when loc is invalid but a file is known (e.g. a file that cannot be opened)
    std::string message;
    uint32_t count =
        1;  // how many times this cause occurred (warnings are reported once per cause)
};

class Diagnostics {
  public:
    void error(SourceLoc loc, std::string message);
    void error_in_file(std::string file, std::string message);
    // Warnings with the same cause are merged: the first place is kept and the rest counted.
    void warning(SourceLoc loc, std::string message, const std::string& cause);
    void warning_in_file(std::string file, std::string message, const std::string& cause);

    // Appends what a reader of a later part of the same text collected, as if this object had
    // collected it: a warning whose cause is known here only adds its count to the first one.
    void append(const Diagnostics& later);

    bool has_errors() const { return error_count_ > 0; }
    size_t error_count() const { return error_count_; }
    size_t warning_count() const;
    const std::vector<Diagnostic>& all() const { return items_; }

    // "FILE:LINE:COL: error: MESSAGE", then the source line and a caret under the column.
    std::string format(const SourceManager& sources) const;
    static std::string format_one(const Diagnostic& d, const SourceManager& sources);

  private:
    std::vector<Diagnostic> items_;
    std::map<std::string, size_t> warning_index_;  // cause -> index in items_
    size_t error_count_ = 0;
};

}  // namespace vr
