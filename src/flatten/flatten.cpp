// flatten_scene: the two passes over the typed scene (bindable nodes first, then the graph) and
// the limits against instancing blow-up.
#include "flatten/flatten.h"

#include <algorithm>
#include <string>

#include "core/huge_pages.h"
#include "flatten/flattener.h"
#include "scene/report.h"
#include "scene/transform.h"

namespace vr::flatten_detail {

FlatScene Flattener::run() {
    if (scene_.groups.empty()) return std::move(out_);
    texture_index_.assign(scene_.textures.size(), kUnloaded);
    mesh_cache_[0].resize(scene_.geometries.size());
    recoveries_.resize(scene_.geometries.size());
    recover_spheres_ = options_.recover_spheres.value_or(options_.spheres == SpheresOption::Gas);
    mesh_cache_[1].resize(scene_.geometries.size());
    mesh_uses_[0].resize(scene_.geometries.size());
    mesh_uses_[1].resize(scene_.geometries.size());
    reserve_primitives();
    appearance_material_.assign(scene_.appearances.size() + 1, -1);

    collect_bindables();
    start_layer();
    choose_viewer();
    out_.light_sets.emplace_back();  // light set 0: no scoped lights
    releasing_ = plan_release();
    visit(frame_.root, Mat4(1.0), 0, 0);
    if (releasing_) give_back_released();
    for (auto& set : out_.light_sets)
        set.insert(set.end(), global_lights_.begin(), global_lights_.end());
    // World meshes whose geometry became a prototype on its second use were left empty.
    std::erase_if(out_.meshes, [](const Mesh& m) { return m.triangles.empty(); });

    stats_.materials = out_.materials.size();
    stats_.lights = out_.lights.size();
    stats_.textures = out_.textures.size();
    return std::move(out_);
}

void Flattener::reserve_primitives() {
    size_t spheres = 0, quadrics = 0, meshes = 0;
    const auto count = [&](sg::Index geometry) {
        const sg::GeometryShape& g = scene_.geometries[geometry].shape;
        if (std::holds_alternative<sg::Sphere>(g))
            ++spheres;
        else if (std::holds_alternative<sg::Box>(g) || std::holds_alternative<sg::Cylinder>(g) ||
                 std::holds_alternative<sg::Cone>(g))
            ++quadrics;
        else if (!std::holds_alternative<std::monostate>(g))
            ++meshes;
    };
    for (const sg::Shape& shape : scene_.shapes) count(shape.geometry);
    for (const sg::TranslatedShape& t : scene_.translated_shapes) count(t.geometry);
    reserve_huge(out_.spheres, spheres);
    reserve_huge(out_.quadrics, quadrics);
    out_.meshes.reserve(meshes);
}

void Flattener::visit(sg::Index g, const Mat4& parent, uint32_t light_set, size_t depth) {
    if (stopped_) return;
    const sg::Group& group = scene_.groups[g];
    if (group.singular && !group.has_transform()) return;  // NaN or inf: nothing to draw
    if (too_deep(depth, group.origin)) return;
    if (++visits_ > options_.max_group_visits) return stop("grouping nodes");
    Mat4 m = parent;
    if (group.transform_kind == sg::GroupTransform::Translation && is_translation(parent)) {
        // The molecule exporters' Transform per atom: the product's other columns are the
        // parent's, and its last one the sum of the translations (the product adds only zeros,
        // which can change no more than a zero's sign), for a 64-multiply product per group.
        const Vec3& t = scene_.translations[group.transform];
        m[3] = Vec4(Vec3(parent[3]) + t, 1.0);
    } else if (group.has_transform()) {
        m = parent * scene_.local_from_child(group);
    }
    const LayoutRect rect_before = layout_rect_;
    if (group.transform_kind == sg::GroupTransform::Layout)
        m = m * layout_matrix(scene_.layouts[group.transform], rect_before, layout_rect_);
    // A zero scale (docs/rendering.md, Zero scales) holds for the whole subtree.
    const bool pressed_before = pressed_flat_;
    pressed_flat_ = pressed_flat_ || group.singular;
    if (group.billboard() && !pressed_flat_) {
        const Mat4 local_from_world = glm::inverse(m);
        const Vec3 viewer = transform_point(local_from_world, viewer_position_);
        const Mat3 local_from_world_linear = glm::inverse(linear_part(m));
        m = m * Mat4(billboard_rotation(scene_.billboard_axes[group.transform], viewer,
                                        local_from_world_linear * viewer_up_,
                                        local_from_world_linear * viewer_back_));
    }

    // Scoped lights among the children light this group's whole subtree.
    const size_t scoped_before = scoped_.size();
    const std::span<const sg::ChildRef> children = scene_.children_of(group);
    for (const sg::ChildRef& c : children)
        if (c.kind == sg::NodeKind::Light && !pressed_flat_) {
            const sg::Light& l = scene_.lights[c.index];
            if (!l.on || l.global) continue;
            if (const auto index = add_light(l, m)) scoped_.push_back(*index);
        }
    if (scoped_.size() != scoped_before) light_set = light_set_of(scoped_);
    const uint32_t scope_before = scope_;
    for (const sg::ChildRef& c : children)
        if ((c.kind == sg::NodeKind::ClipPlane || c.kind == sg::NodeKind::LocalFog) &&
            !pressed_flat_) {
            scope_ = enter_scope(children, m);
            break;
        }
    visit_children(group, m, light_set, depth);
    scope_ = scope_before;
    pressed_flat_ = pressed_before;
    layout_rect_ = rect_before;
    scoped_.resize(scoped_before);
}

bool Flattener::too_deep(size_t depth, const sg::Origin& origin) {
    if (depth <= options_.max_depth) return false;
    if (!depth_warned_)
        NodeReport(diagnostics_, origin)
            .warn("depth", "is nested more than " + std::to_string(options_.max_depth) +
                               " levels deep; skipped");
    depth_warned_ = true;
    return true;
}

void Flattener::visit_translated(const sg::TranslatedShape& t, const Mat4& parent,
                                 uint32_t light_set, size_t depth) {
    // visit()'s steps for a group that is not singular, translates, and holds one Shape.
    if (stopped_ || too_deep(depth, t.group_origin())) return;
    if (++visits_ > options_.max_group_visits) return stop("grouping nodes");
    Mat4 m = parent;
    if (is_translation(parent))
        m[3] = Vec4(Vec3(parent[3]) + t.translation, 1.0);
    else
        m = parent * translation_matrix(t.translation);
    emit_shape(t.shape(), m, light_set);
}

void Flattener::visit_children(const sg::Group& group, const Mat4& m, uint32_t light_set,
                               size_t depth) {
    // A molecule export's atoms are the root's children: its typed nodes go as the walk passes.
    const bool releasing = releasing_ && &group == &scene_.groups[Scene::kRoot];
    constexpr size_t kReleaseEvery = 4096;  // children between two releases
    const std::span<const sg::ChildRef> children = scene_.children_of(group);
    for (size_t k = 0; k < children.size(); ++k) {
        const sg::ChildRef& c = children[k];
        if (releasing && k % kReleaseEvery == 0 && k > 0) release_before(c);
        switch (c.kind) {
            case sg::NodeKind::Group:
                visit(c.index, m, light_set, depth + 1);
                break;
            case sg::NodeKind::Shape:
                emit_shape(scene_.shapes[c.index], m, light_set);
                break;
            case sg::NodeKind::TranslatedShape:
                visit_translated(scene_.translated_shapes[c.index], m, light_set, depth + 1);
                break;
            case sg::NodeKind::Light: {
                const sg::Light& l = scene_.lights[c.index];
                if (l.on && l.global && !pressed_flat_)
                    if (const auto index = add_light(l, m)) global_lights_.push_back(*index);
                break;
            }
            default:
                break;  // bindable nodes: first pass; ClipPlane, LocalFog: the scope above
        }
    }
}

void Flattener::stop(const char* what) {
    if (!stopped_)
        diagnostics_.error(
            SourceLoc{},
            std::string("the scene expands to more ") + what +
                " than the limit allows (DEF/USE instancing); the rest is not rendered");
    stopped_ = true;
}

bool Flattener::gas_of(const Material& m) const {
    if (m.sphere_mode >= 0) return m.sphere_mode == int8_t(SphereMode::Gas);
    return options_.spheres == SpheresOption::Gas;
}

}  // namespace vr::flatten_detail

namespace vr {

const char* recovery_miss_label(RecoveryMiss m) {
    switch (m) {
        case RecoveryMiss::Textured:
            return "textured";
        case RecoveryMiss::Colored:
            return "per-vertex colours";
        case RecoveryMiss::NonUniformGas:
            return "a sphere under a non-uniform scale in gas mode";
        case RecoveryMiss::kCount:
            break;
        default:
            return fit_failure_label(FitFailure(m));
    }
    return "?";
}

FlatScene flatten_scene(const Scene& scene, const FlattenOptions& options, Diagnostics& diagnostics,
                        FlattenStats& stats) {
    stats = FlattenStats{};
    if (!scene.layers.empty()) return flatten_layers(scene, options, diagnostics, stats);
    flatten_detail::Flattener flattener(scene, options, diagnostics, stats);
    return flattener.run();
}

FlatScene flatten_scene_releasing(Scene& scene, const FlattenOptions& options,
                                  Diagnostics& diagnostics, FlattenStats& stats) {
    stats = FlattenStats{};
    if (!scene.layers.empty()) return flatten_layers(scene, options, diagnostics, stats);
    flatten_detail::Flattener flattener(scene, options, diagnostics, stats);
    flattener.release_behind(scene);
    return flattener.run();
}

}  // namespace vr
