// UTF-16 text with a byte-order mark, as some Windows tools save VRML and X3D files: converted to
// UTF-8 before any reader sees it, so that every reader, offset and message works on UTF-8.
#pragma once
#include <optional>
#include <string>
#include <string_view>

namespace vr {

// The UTF-8 form of `bytes` when they start with a UTF-16 byte-order mark (FF FE little-endian,
// FE FF big-endian), without the mark; nothing when they do not. A line break stays one line
// break, so lines are those of the file; columns count UTF-8 bytes. An unpaired surrogate and a
// last odd byte become U+FFFD, as a text editor shows them.
std::optional<std::string> utf8_from_utf16(std::string_view bytes);

}  // namespace vr
