#include "parser/field_type.h"

#include <array>
#include <string>

namespace vr {
namespace {

struct KindInfo {
    ValueKind kind;
    const char* sf;
    const char* mf;
    int components;
};

constexpr std::array<KindInfo, 21> kKinds = {{
    {ValueKind::Bool, "SFBool", "MFBool", 1},
    {ValueKind::Int32, "SFInt32", "MFInt32", 1},
    {ValueKind::Float, "SFFloat", "MFFloat", 1},
    {ValueKind::Double, "SFDouble", "MFDouble", 1},
    {ValueKind::Time, "SFTime", "MFTime", 1},
    {ValueKind::String, "SFString", "MFString", 0},
    {ValueKind::Vec2f, "SFVec2f", "MFVec2f", 2},
    {ValueKind::Vec3f, "SFVec3f", "MFVec3f", 3},
    {ValueKind::Vec4f, "SFVec4f", "MFVec4f", 4},
    {ValueKind::Vec2d, "SFVec2d", "MFVec2d", 2},
    {ValueKind::Vec3d, "SFVec3d", "MFVec3d", 3},
    {ValueKind::Vec4d, "SFVec4d", "MFVec4d", 4},
    {ValueKind::Rotation, "SFRotation", "MFRotation", 4},
    {ValueKind::Color, "SFColor", "MFColor", 3},
    {ValueKind::ColorRGBA, "SFColorRGBA", "MFColorRGBA", 4},
    {ValueKind::Image, "SFImage", "MFImage", 0},
    {ValueKind::Node, "SFNode", "MFNode", 0},
    {ValueKind::Matrix3f, "SFMatrix3f", "MFMatrix3f", 9},
    {ValueKind::Matrix4f, "SFMatrix4f", "MFMatrix4f", 16},
    {ValueKind::Matrix3d, "SFMatrix3d", "MFMatrix3d", 9},
    {ValueKind::Matrix4d, "SFMatrix4d", "MFMatrix4d", 16},
}};

const KindInfo& info(ValueKind kind) { return kKinds[static_cast<size_t>(kind)]; }

constexpr bool components_agree() {
    for (size_t i = 0; i < kKinds.size(); ++i)
        if (static_cast<size_t>(kKinds[i].kind) != i || kKinds[i].components != kComponents[i])
            return false;
    return sizeof kComponents == kKinds.size();
}
static_assert(components_agree(), "kComponents in field_type.h disagrees with kKinds");

}  // namespace

bool is_numeric(ValueKind kind) { return kind != ValueKind::String && kind != ValueKind::Node; }

std::string_view type_name(FieldType type) {
    return type.multi ? info(type.kind).mf : info(type.kind).sf;
}

std::optional<FieldType> parse_type_name(std::string_view name) {
    for (const KindInfo& k : kKinds) {
        if (name == k.sf) return FieldType{k.kind, false};
        if (name == k.mf) return FieldType{k.kind, true};
    }
    return std::nullopt;
}

std::optional<Access> parse_access(std::string_view w) {
    if (w == "field" || w == "initializeOnly" || w == "[]") return Access::Field;
    if (w == "exposedField" || w == "inputOutput" || w == "[in,out]") return Access::ExposedField;
    if (w == "eventIn" || w == "inputOnly" || w == "[in]") return Access::EventIn;
    if (w == "eventOut" || w == "outputOnly" || w == "[out]") return Access::EventOut;
    return std::nullopt;
}

std::string_view access_name_vrml97(Access a) {
    switch (a) {
        case Access::Field:
            return "field";
        case Access::ExposedField:
            return "exposedField";
        case Access::EventIn:
            return "eventIn";
        case Access::EventOut:
            return "eventOut";
    }
    return "field";
}

std::string_view access_name_x3d(Access a) {
    switch (a) {
        case Access::Field:
            return "initializeOnly";
        case Access::ExposedField:
            return "inputOutput";
        case Access::EventIn:
            return "inputOnly";
        case Access::EventOut:
            return "outputOnly";
    }
    return "initializeOnly";
}

}  // namespace vr
