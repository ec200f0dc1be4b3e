// The compact record of a molecule exporter's atom (sg::TranslatedShape in scene.h): when a built
// Transform and its one Shape fit one, and what they were.
#pragma once
#include <optional>

#include "scene/scene.h"

namespace vr {

// The record for `group`, a Transform with the translation `translation` whose only drawn child
// is `shape`; nullopt when the pair holds more than a record keeps (another transform, a DEF,
// hints, the Shape in another file or more than 255 bytes after the Transform). Both builds (the
// node tree's, detail::Builder, and a plain piece's, plain_piece.cpp) ask it the same question,
// so that their scenes stay equal index for index; the tree's build also keeps a Transform a
// group when it or a child is shared (a plain piece shares nothing).
std::optional<sg::TranslatedShape> translated_shape(const sg::Group& group, const Vec3& translation,
                                                    const sg::Shape& shape);

}  // namespace vr
