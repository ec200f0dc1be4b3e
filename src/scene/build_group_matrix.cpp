// A group's matrix (Transform's fields, or MatrixTransform's `matrix`) into the scene's side
// arrays, and MatrixTransform's matrix read from its sixteen numbers.
#include <cmath>

#include "scene/build_internal.h"
#include "scene/transform.h"

namespace vr::detail {

void Builder::set_group_matrix(sg::Group& group, NodeId id, const Mat4& m) {
    if (!all_finite(m)) {
        group.singular = true;  // flattening skips the subtree: no matrix to keep
        warn(id, "singular", "has a NaN or infinite transform value; its children are skipped");
    } else if (is_singular(m)) {
        // A zero scale presses the subtree into a plane or a line, as a browser draws it; the
        // matrix is kept and flattening draws meshes flat (docs/rendering.md, Zero scales).
        group.singular = true;
        group.transform_kind = sg::GroupTransform::Matrix;
        group.transform = static_cast<sg::Index>(scene_.matrices.size());
        scene_.matrices.push_back(m);
        warn(id, "singular",
             "has a singular transform (a zero scale): its meshes, lines and points are drawn "
             "pressed flat; spheres, boxes, cylinders, cones, lights and viewpoints in it are "
             "skipped");
    } else if (is_translation(m)) {
        group.transform_kind = sg::GroupTransform::Translation;
        group.transform = static_cast<sg::Index>(scene_.translations.size());
        scene_.translations.push_back(Vec3(m[3]));
    } else {
        group.transform_kind = sg::GroupTransform::Matrix;
        group.transform = static_cast<sg::Index>(scene_.matrices.size());
        scene_.matrices.push_back(m);
    }
}

Mat4 Builder::matrix_transform(NodeId id) {
    // Castle's and FreeWRL's files write the matrix as four groups of four with the translation in
    // the last group (grammar/x3d.nodes): group i is column i of the matrix that maps a child's
    // point p to M p, glm's own order.
    const FieldView v = read(id, "matrix"_n, Many::SF, {ValueKind::Matrix4f, ValueKind::Matrix4d});
    Mat4 m(1.0);
    if (v.numbers.size() != 16) return m;
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = v.numbers[4 * c + r];
    const Vec4 last_row(m[0][3], m[1][3], m[2][3], m[3][3]);
    if (last_row == Vec4(0.0, 0.0, 0.0, 1.0)) return m;
    // A homogeneous scale (the last row 0 0 0 w) divides out; a projective part has no meaning for
    // the ray tracer's affine instances and is dropped.
    const double w = last_row.w;
    if (last_row.x != 0.0 || last_row.y != 0.0 || last_row.z != 0.0 || w == 0.0)
        warn(id, "projective",
             "matrix has a projective part (its last row is not 0 0 0 w, w != 0); it is ignored");
    if (w != 0.0 && std::isfinite(w))
        for (int c = 0; c < 4; ++c) m[c] /= w;
    for (int c = 0; c < 3; ++c) m[c][3] = 0.0;
    m[3][3] = 1.0;
    return m;
}

}  // namespace vr::detail
