#include "parser/units.h"

#include <charconv>
#include <cmath>
#include <unordered_set>

#include "parser/registry.h"

namespace vr {

std::string add_unit(FileUnits& units, std::string_view category, std::string_view factor,
                     SourceLoc where) {
    double* slot = category == "length"  ? &units.length
                   : category == "angle" ? &units.angle
                   : category == "mass"  ? &units.mass
                   : category == "force" ? &units.force
                                         : nullptr;
    if (!slot)
        return "UNIT category '" + std::string(category) +
               "' is not one of angle, force, length, mass; the statement is ignored";
    double value = 0.0;
    const auto [end, ec] = std::from_chars(factor.data(), factor.data() + factor.size(), value);
    if (ec != std::errc() || end != factor.data() + factor.size() || !std::isfinite(value) ||
        value <= 0.0)
        return "UNIT " + std::string(category) + ": the conversion factor '" + std::string(factor) +
               "' is not a positive number; the statement is ignored";
    // 7.2.5.5: at most one UNIT statement per category.
    static constexpr const char* kSeen[] = {"length", "angle", "mass", "force"};
    const size_t bit = static_cast<size_t>(slot - &units.length);
    if (units.seen >> bit & 1u)
        return "a second UNIT " + std::string(kSeen[bit]) + " statement; the first one is kept";
    *slot = value;
    units.seen = static_cast<uint8_t>(units.seen | 1u << bit);
    if (!units.any()) units.first = where;
    return {};
}

bool units_allowed(std::string_view version) {
    int major = 0, minor = 0;
    const char* p = version.data();
    const char* end = p + version.size();
    auto r = std::from_chars(p, end, major);
    if (r.ec != std::errc()) return false;
    if (r.ptr < end && *r.ptr == '.') std::from_chars(r.ptr + 1, end, minor);
    return major > 3 || (major == 3 && minor >= 3);
}

bool is_angle_field(const NodeTypeDecl* decl, Name type, Name field, FieldType field_type) {
    if (field_type.kind == ValueKind::Rotation) return true;
    if (field_type.kind != ValueKind::Float) return false;
    static const Name kCrease = intern("creaseAngle"), kRotation = intern("rotation"),
                      kTextureTransform = intern("TextureTransform");
    if (field == kCrease) return true;
    if (field == kRotation && type == kTextureTransform) return true;
    const FieldDecl* f = decl ? decl->find(field) : nullptr;
    // The specifications write every angle range in pi ((0,pi), [-2pi,2pi], ...) and no other.
    return f && f->range.find("pi") != std::string::npos;
}

void convert_angles(NodeTree& tree, uint32_t file, size_t first_node, double factor) {
    if (factor == 1.0) return;
    // PROTO instances may share one value's numbers; each number is converted once.
    std::unordered_set<uint32_t> done;
    for (size_t id = first_node; id < tree.nodes.size(); ++id) {
        const auto node = static_cast<NodeId>(id);
        for (const FieldEntry& e : tree.set_fields(node)) {
            if (e.loc.get().file != file) continue;  // a PROTO body of another file
            if (!is_angle_field(tree.decl(node), tree.type(node), e.name, e.type)) continue;
            if (!done.insert(e.begin).second) continue;
            const uint32_t step = e.type.kind == ValueKind::Rotation ? 4 : 1;
            const uint32_t first = e.type.kind == ValueKind::Rotation ? 3 : 0;
            for (uint32_t i = first; i < e.count; i += step) tree.numbers[e.begin + i] *= factor;
        }
    }
}

}  // namespace vr
