// Lights and bindable nodes (Viewpoint, Background, Fog, NavigationInfo), the Billboard rotation
// that faces the chosen viewpoint.
#include <algorithm>
#include <cmath>

#include "core/format.h"
#include "flatten/flattener.h"
#include "scene/report.h"
#include "scene/transform.h"

namespace vr::flatten_detail {

namespace {

double finite_or(double d, double fallback) { return std::isfinite(d) ? d : fallback; }
Vec3 finite_or(const Vec3& v, const Vec3& fallback) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) ? v : fallback;
}

}  // namespace

Mat3 billboard_rotation(const Vec3& axis, const Vec3& viewer_local, const Vec3& viewer_up_local,
                        const Vec3& viewer_back_local) {
    const double to_viewer = glm::length(viewer_local);
    if (!(to_viewer > 0.0) || !std::isfinite(to_viewer)) return Mat3(1.0);
    const double axis_length = glm::length(axis);
    if (!(axis_length > 0.0)) {
        // Screen-aligned: +Z along the camera's backward axis, +Y along the camera's up.
        const double back_length = glm::length(viewer_back_local);
        if (!(back_length > 0.0) || !std::isfinite(back_length)) return Mat3(1.0);
        const Vec3 z = viewer_back_local / back_length;
        Vec3 y = viewer_up_local - glm::dot(viewer_up_local, z) * z;
        const double y_length = glm::length(y);
        if (!(y_length > 1e-12)) return Mat3(1.0);
        y /= y_length;
        return Mat3(glm::cross(y, z), y, z);
    }
    const Vec3 a = axis / axis_length;
    const Vec3 w = viewer_local -
                   glm::dot(viewer_local, a) * a;  // viewer direction in the plane across the axis
    const Vec3 z = Vec3(0, 0, 1) - a.z * a;        // local +Z in that plane
    if (!(glm::length(w) > 1e-12 * to_viewer) || !(glm::length(z) > 1e-12)) return Mat3(1.0);
    const double angle = std::atan2(glm::dot(a, glm::cross(z, w)), glm::dot(z, w));
    return rotation_matrix(a, angle);
}

void Flattener::mark_bindables() {
    const size_t n = scene_.groups.size();
    has_bindable_.assign(n, 0);
    // Molecule exports put their Viewpoint and NavigationInfo among the top-level nodes. When
    // every reference to a bindable node is in the root's own block, no other group holds one:
    // a scan of the references answers without the passes over millions of groups (a fifth of
    // their cost on a large molecule: bench/README.md, "Figures behind the comments").
    const auto bindable = [](const sg::ChildRef& c) {
        return c.index != sg::kNone && c.kind != sg::NodeKind::Group &&
               c.kind != sg::NodeKind::Shape && c.kind != sg::NodeKind::Light &&
               c.kind != sg::NodeKind::TranslatedShape;
    };
    size_t at_top = 0, anywhere = 0;
    for (const sg::ChildRef& c : scene_.children_of(scene_.groups[Scene::kRoot]))
        at_top += bindable(c) ? 1 : 0;
    for (const sg::ChildRef& c : scene_.child_refs) anywhere += bindable(c) ? 1 : 0;
    if (anywhere == at_top) {
        has_bindable_[Scene::kRoot] = at_top > 0 ? 1 : 0;
        return;
    }
    // A file's nesting lists every group before its child groups, so one backward pass sees each
    // child's answer before its parent needs it: a sequential pass over millions of groups where
    // the walk below chases every child. A child listed before its parent (USE of an earlier DEF)
    // leaves the answer to the walk.
    for (size_t g = n; g-- > 0;) {
        uint8_t any = 0;
        for (const sg::ChildRef& c : scene_.children_of(scene_.groups[g])) {
            if (c.kind == sg::NodeKind::Group) {
                if (c.index <= g) return mark_bindables_walk();
                any |= has_bindable_[c.index];
            } else if (c.kind != sg::NodeKind::Shape && c.kind != sg::NodeKind::Light &&
                       c.kind != sg::NodeKind::TranslatedShape) {
                any = 1;
            }
        }
        has_bindable_[g] = any;
    }
}

void Flattener::mark_bindables_walk() {
    const size_t n = scene_.groups.size();
    has_bindable_.assign(n, 0);
    std::vector<uint8_t> state(n, 0);  // 0 new, 1 on the stack, 2 done
    std::vector<std::pair<sg::Index, size_t>> stack;
    for (sg::Index start = 0; start < n; ++start) {
        if (state[start] != 0) continue;
        state[start] = 1;
        stack.emplace_back(start, 0);
        while (!stack.empty()) {
            auto& [g, next] = stack.back();
            const std::span<const sg::ChildRef> children = scene_.children_of(scene_.groups[g]);
            if (next < children.size()) {
                const sg::ChildRef c = children[next++];
                if (c.kind != sg::NodeKind::Group) {
                    if (c.kind != sg::NodeKind::Shape && c.kind != sg::NodeKind::Light &&
                        c.kind != sg::NodeKind::TranslatedShape)
                        has_bindable_[g] = 1;
                } else if (state[c.index] == 2) {
                    has_bindable_[g] |= has_bindable_[c.index];
                } else if (state[c.index] == 0) {
                    state[c.index] = 1;
                    stack.emplace_back(c.index, 0);
                }
                continue;
            }
            const sg::Index done = g;
            state[done] = 2;
            stack.pop_back();
            if (!stack.empty()) has_bindable_[stack.back().first] |= has_bindable_[done];
        }
    }
}

void Flattener::collect_bindables() {
    mark_bindables();
    collect(frame_.root, Mat4(1.0), false, 0);
}

void Flattener::collect(sg::Index g, const Mat4& parent, bool in_inline, size_t depth) {
    const sg::Group& group = scene_.groups[g];
    if (group.singular || depth > options_.max_depth || !has_bindable_[g]) return;
    if (++collect_visits_ > options_.max_primitives)
        return;  // instancing blow-up: visit() reports it
    const Mat4 m = group.has_transform() ? parent * scene_.local_from_child(group) : parent;
    in_inline = in_inline || group.inline_content;
    Bindables& b = in_inline ? inlined_ : main_;
    for (const sg::ChildRef& c : scene_.children_of(group)) {
        switch (c.kind) {
            case sg::NodeKind::Group:
                // Tested here, not on entry: most groups hold none, and their records stay unread.
                if (has_bindable_[c.index]) collect(c.index, m, in_inline, depth + 1);
                break;
            case sg::NodeKind::Viewpoint:
                b.viewpoints.push_back(make_viewpoint(scene_.viewpoints[c.index], m));
                break;
            case sg::NodeKind::Background:
                if (!b.background) b.background = make_background(scene_.backgrounds[c.index], m);
                break;
            case sg::NodeKind::Fog:
                if (!b.fog) b.fog = make_fog(scene_.fogs[c.index], m);
                break;
            case sg::NodeKind::NavigationInfo:
                if (!b.headlight) b.headlight = scene_.navigation_infos[c.index].headlight;
                break;
            default:
                break;
        }
    }
}

Viewpoint Flattener::make_viewpoint(const sg::Viewpoint& v, const Mat4& m) {
    Viewpoint out;
    out.def_name = v.def_name;
    out.description = v.description;
    out.ortho = v.ortho;
    const Mat3 linear = linear_part(m);
    out.position = transform_point(m, finite_or(v.position, Vec3(0.0, 0.0, 10.0)));
    out.world_from_camera = orthonormalize(linear) * rotation_matrix(v.orientation);
    out.field_of_view = v.field_of_view;  // checked by the scene build
    const double s = mean_scale(linear);
    for (int i = 0; i < 4; ++i) out.ortho_extent[i] = v.ortho_extent[i] * s;
    return out;
}

Background Flattener::make_background(const sg::Background& b, const Mat4& m) {
    Background out;
    out.present = true;
    out.world_from_background = orthonormalize(linear_part(m));
    out.sky_colors = b.sky_color;
    out.sky_angles = b.sky_angle;
    out.ground_colors = b.ground_color;
    out.ground_angles = b.ground_angle;
    // Colours and angles already match (the scene build made them).
    for (int face = 0; face < 6; ++face) {
        if (b.urls[face].empty()) continue;
        TextureSampling clamped;  // a cube face never wraps
        clamped.wrap_s = clamped.wrap_t = TextureWrap::ClampToEdge;
        out.panorama[face] = load_image(b.urls[face], b.from_file, clamped, b.origin);
    }
    return out;
}

Fog Flattener::make_fog(const sg::Fog& f, const Mat4& m) {
    Fog out;
    out.color = f.color;
    out.visibility_range = f.visibility_range * mean_scale(linear_part(m));
    if (!(out.visibility_range > 0.0) || !std::isfinite(out.visibility_range)) {
        out.visibility_range = 0.0;
        return out;  // 0 disables fog
    }
    out.kind = f.exponential ? FogKind::Exponential : FogKind::Linear;
    return out;
}

void Flattener::choose_viewer() {
    out_.viewpoints = std::move(main_.viewpoints);
    out_.viewpoints.insert(out_.viewpoints.end(), inlined_.viewpoints.begin(),
                           inlined_.viewpoints.end());
    if (main_.background)
        out_.background = *main_.background;
    else if (inlined_.background)
        out_.background = *inlined_.background;
    if (main_.fog)
        out_.fog = *main_.fog;
    else if (inlined_.fog)
        out_.fog = *inlined_.fog;
    out_.headlight = main_.headlight ? *main_.headlight : inlined_.headlight.value_or(true);

    const Viewpoint* chosen = out_.viewpoints.empty() ? nullptr : &out_.viewpoints.front();
    if (!options_.viewpoint.empty()) {
        for (const Viewpoint& v : out_.viewpoints)
            if (v.def_name == options_.viewpoint || v.description == options_.viewpoint) {
                chosen = &v;
                break;
            }
    }
    if (chosen) {
        viewer_position_ = chosen->position;
        viewer_up_ = chosen->world_from_camera[1];
        viewer_back_ = chosen->world_from_camera[2];
    }
}

uint32_t Flattener::light_set_of(const std::vector<uint32_t>& lights) {
    const auto [it, inserted] =
        light_set_index_.try_emplace(lights, uint32_t(out_.light_sets.size()));
    if (inserted) out_.light_sets.push_back(lights);
    return it->second;
}

std::optional<uint32_t> Flattener::add_light(const sg::Light& l, const Mat4& m) {
    NodeReport report(diagnostics_, l.origin);
    Light out;
    out.kind = l.type == sg::LightType::Directional ? LightKind::Directional
               : l.type == sg::LightType::Point     ? LightKind::Point
                                                    : LightKind::Spot;
    out.color = finite_or(l.color, Vec3(1.0));
    out.intensity = finite_or(l.intensity, 1.0);
    out.ambient_intensity = finite_or(l.ambient_intensity, 0.0);
    out.attenuation = finite_or(l.attenuation, Vec3(1.0, 0.0, 0.0));
    out.beam_width = finite_or(l.beam_width, out.beam_width);
    out.cutoff_angle = finite_or(l.cut_off_angle, out.cutoff_angle);
    out.angular_radius = l.angular_radius;
    const Mat3 linear = linear_part(m);
    if (out.kind != LightKind::Point) {
        const Vec3 d = linear * l.direction;
        const double length = glm::length(d);
        if (!(length > 0.0) || !std::isfinite(length)) {
            report.warn("direction", "direction is zero or not finite; the light is dropped");
            return std::nullopt;
        }
        out.direction = d / length;
    }
    if (out.kind != LightKind::Directional) {
        out.position = transform_point(m, l.location);
        out.radius = l.radius * mean_scale(linear);
        out.source_radius = l.source_radius * mean_scale(linear);
        if (!std::isfinite(out.position.x + out.position.y + out.position.z) ||
            !(out.radius >= 0.0)) {
            report.warn("location",
                        "location or radius is not finite or negative; the light is dropped");
            return std::nullopt;
        }
    }
    out_.lights.push_back(out);
    return uint32_t(out_.lights.size() - 1);
}

}  // namespace vr::flatten_detail
