// Opening an image file for writing. Re-rendering to the same path is the common case, so an
// existing file is written over in place and cut to the new length at the end, not truncated
// first: truncating frees the old page-cache pages and the write then allocates new ones, a third
// of a large PPM's write (bench/README.md, "Figures behind the comments"). The file ends the same
// either way.
#pragma once
#include <cstdio>
#include <string>

namespace vr {

// The file at `path`, created if missing, positioned at its start; null (and `error` set from
// errno) when it cannot be opened.
FILE* open_output(const std::string& path, std::string& error);

// Flushes, cuts a regular file to what was written, closes. False (`error` set) on any failure;
// `f` is closed either way.
bool close_output(FILE* f, std::string& error);

}  // namespace vr
