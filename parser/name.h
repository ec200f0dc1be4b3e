// Interned names (node types, field names, DEF names): compared as integers, printed as text.
#pragma once
#include <cstdint>
#include <string_view>

namespace vr {

using Name = uint32_t;
constexpr Name kNoName = 0;  // the empty name

// Thread-safe; the returned views stay valid for the life of the program.
Name intern(std::string_view text);
std::string_view name_text(Name name);

}  // namespace vr
