#include "scene/translated_shape.h"

namespace vr {

namespace {
const Name kTransform = intern("Transform");
const Name kShape = intern("Shape");
}  // namespace

sg::Origin sg::TranslatedShape::group_origin() const {
    return Origin{kTransform, kNoName, transform_loc};
}

sg::Shape sg::TranslatedShape::shape() const {
    Shape s;
    const SourceLoc at = transform_loc.get();
    s.origin = Origin{kShape, kNoName, SourceLoc{at.file, at.offset + shape_delta}};
    s.appearance = appearance;
    s.geometry = geometry;
    return s;
}

std::optional<sg::TranslatedShape> translated_shape(const sg::Group& group, const Vec3& translation,
                                                    const sg::Shape& shape) {
    if (group.transform_kind != sg::GroupTransform::Translation || group.singular ||
        group.inline_content || group.origin.type != kTransform ||
        group.origin.def_name != kNoName || shape.origin.type != kShape ||
        shape.origin.def_name != kNoName || shape.hints != sg::kNone)
        return std::nullopt;
    const SourceLoc at = group.origin.loc.get(), shape_at = shape.origin.loc.get();
    if (!at.valid() || shape_at.file != at.file || shape_at.offset < at.offset ||
        shape_at.offset - at.offset > UINT8_MAX)
        return std::nullopt;
    sg::TranslatedShape t;
    t.translation = translation;
    t.transform_loc = group.origin.loc;
    t.shape_delta = static_cast<uint8_t>(shape_at.offset - at.offset);
    t.appearance = shape.appearance;
    t.geometry = shape.geometry;
    return t;
}

}  // namespace vr
