// Reading field values of a known type, the same way for scene files, X3D XML attributes and the
// grammar tables' defaults. SFNode/MFNode values other than NULL and [] are read by the node
// readers.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>

#include "parser/diagnostics.h"
#include "parser/field_type.h"
#include "parser/lexer.h"
#include "parser/node_tree.h"

namespace vr {

// Thrown by the readers for a syntax error at a byte offset of the current file; caught at the top
// of a reader and turned into one Diagnostic.
struct SyntaxError {
    SourceOffset offset;
    std::string message;
};

struct ValueContext {
    NodeTree& tree;
    Lexer& lexer;
    Diagnostics* diagnostics =
        nullptr;                 // for warnings (e.g. rotation axes normalised); may be null
    uint32_t file = UINT32_MAX;  // source file index for warning locations
    size_t max_values = size_t(1) << 28;  // numbers or strings one field may hold
    bool xml = false;                     // X3D XML attribute: true/false accepted, no brackets
};

// Appends one value of `type` to the tree's pools and fills entry.type/begin/count.
// Node kinds accept only NULL (SF) or [] (MF) here.
void read_field_value(ValueContext& ctx, FieldType type, FieldEntry& entry);

// Number words: decimal or hex integers, floats with optional sign, '.5', '1.', '1E+5'.
bool parse_double(std::string_view word, double& out);
bool parse_int32(std::string_view word,
                 int64_t& out);  // accepts hex up to 0xFFFFFFFF (as unsigned)

// An SFInt32/MFInt32 value as int32. parse_int32 keeps a hex value as its unsigned 32-bit pattern
// (SFImage pixels need 0xFFFFFFFF), which an integer field reads as the pattern's two's-complement
// value, as C does: 0xFFFFFFFF is -1. A negated hex beyond -2^31 has no int32 and gives `invalid`.
inline int32_t int32_of_number(double d, int32_t invalid) {
    if (d >= -2147483648.0 && d <= 2147483647.0) return static_cast<int32_t>(d);
    if (d > 2147483647.0 && d <= 4294967295.0)
        return static_cast<int32_t>(static_cast<uint32_t>(d));
    return invalid;
}

// Normalises an SFRotation axis in place; returns false only for a zero axis with a non-zero angle,
// which names no rotation (worth a warning).
bool normalise_rotation(double* r);

}  // namespace vr
