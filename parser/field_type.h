// The field types of VRML97 and X3D, and how many numbers one value of each holds.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace vr {

enum class ValueKind : uint8_t {
    Bool,
    Int32,
    Float,
    Double,
    Time,
    String,
    Vec2f,
    Vec3f,
    Vec4f,
    Vec2d,
    Vec3d,
    Vec4d,
    Rotation,
    Color,
    ColorRGBA,
    Image,
    Node,
    Matrix3f,
    Matrix4f,
    Matrix3d,
    Matrix4d,
};

// One byte, so that the node tree's FieldEntry packs into 20 bytes.
// (Constructors rather than member initializers: GCC 12 rejects `return {}` for aggregates holding
// bit-fields with default member initializers.)
struct FieldType {
    ValueKind kind : 7;
    bool multi : 1;  // MF (true) or SF (false)
    constexpr FieldType() : kind(ValueKind::Float), multi(false) {}
    constexpr FieldType(ValueKind k, bool mf = false) : kind(k), multi(mf) {}
    bool operator==(const FieldType&) const = default;
};
static_assert(sizeof(FieldType) == 1);

// Numbers in one value of this kind (SFImage: 0, it is variable; String and Node: 0, they are not
// numbers). Inline: the readers ask once per value. field_type.cpp checks the table against the
// kind table.
inline constexpr int8_t kComponents[] = {1, 1, 1, 1, 1, 0, 2, 3,  4, 2, 3,
                                         4, 4, 3, 4, 0, 0, 9, 16, 9, 16};
inline int components(ValueKind kind) { return kComponents[static_cast<size_t>(kind)]; }
bool is_numeric(ValueKind kind);
// "SFVec3f", "MFNode", ...
std::string_view type_name(FieldType type);
std::optional<FieldType> parse_type_name(std::string_view name);

// How a field may be used: VRML97 field/exposedField/eventIn/eventOut, X3D
// initializeOnly/inputOutput/...
enum class Access : uint8_t { Field, ExposedField, EventIn, EventOut };
std::optional<Access> parse_access(
    std::string_view word);  // both VRML97 and X3D spellings, and [in,out] forms
std::string_view access_name_vrml97(Access access);
std::string_view access_name_x3d(Access access);
inline bool has_value(Access access) {
    return access == Access::Field || access == Access::ExposedField;
}

}  // namespace vr
