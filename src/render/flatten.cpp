#include "render/flatten.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <unordered_map>

#include "core/format.h"
#include "core/huge_pages.h"
#include "geometry/cylinder_fit.h"
#include "geometry/mesh_nodes.h"
#include "geometry/sphere_fit.h"
#include "parser/load.h"
#include "image/texture_file.h"
#include "scene/report.h"
#include "scene/transform.h"

namespace vr {

namespace {

// Every field of a Material, as doubles: equal keys are equal materials.
using MaterialKey = std::array<double, 34>;

MaterialKey key_of(const Material& m) {
    MaterialKey k{};
    size_t i = 0;
    auto put = [&](double d) { k[i++] = d == 0.0 ? 0.0 : d; };  // -0 and +0 are one material
    auto put3 = [&](const Vec3& v) { put(v.x), put(v.y), put(v.z); };
    put(m.lit);
    put3(m.diffuse);
    put3(m.specular);
    put3(m.emissive);
    put(m.ambient_intensity);
    put(m.shininess);
    put(m.transparency);
    put(m.reflectivity);
    put(m.ior);
    put(m.texture);
    for (int c = 0; c < 3; ++c) put3(m.texture_transform[c]);
    put(m.sphere_mode);
    put(m.density);
    put3(m.albedo);
    put3(m.emission);
    return k;
}

struct MaterialKeyHash {
    size_t operator()(const MaterialKey& k) const {
        uint64_t h = 0x9E3779B97F4A7C15ull;
        for (double d : k) {  // a multiply-xorshift mix a word
            uint64_t bits;
            std::memcpy(&bits, &d, sizeof bits);
            h = (h ^ bits) * 0xFF51AFD7ED558CCDull;
            h ^= h >> 32;
        }
        return size_t(h);
    }
};
struct MaterialKeyEqual {
    bool operator()(const MaterialKey& a, const MaterialKey& b) const {
        return std::memcmp(a.data(), b.data(), sizeof(MaterialKey)) == 0;
    }
};

double finite_or(double d, double fallback) { return std::isfinite(d) ? d : fallback; }
Vec3 finite_or(const Vec3& v, const Vec3& fallback) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) ? v : fallback;
}

// The rotation a Billboard applies to its children, given the viewer in the billboard's local space
// (position, and the camera's up and backward directions).
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

class Flattener {
  public:
    Flattener(const Scene& scene, const FlattenOptions& options, Diagnostics& diagnostics,
              FlattenStats& stats)
        : scene_(scene), options_(options), diagnostics_(diagnostics), stats_(stats) {}

    FlatScene run() {
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
        choose_viewer();
        out_.light_sets.emplace_back();  // light set 0: no scoped lights
        visit(Scene::kRoot, Mat4(1.0), 0, 0);
        for (auto& set : out_.light_sets)
            set.insert(set.end(), global_lights_.begin(), global_lights_.end());
        // World meshes whose geometry became a prototype on its second use were left empty.
        std::erase_if(out_.meshes, [](const Mesh& m) { return m.triangles.empty(); });

        stats_.materials = out_.materials.size();
        stats_.lights = out_.lights.size();
        stats_.textures = out_.textures.size();
        return std::move(out_);
    }

  private:
    static constexpr int32_t kUnloaded = -2;

    // Room for one primitive a shape node (a guess: USE may add more), so that 1e5 primitives are not
    // moved by doubling.
    void reserve_primitives() {
        size_t spheres = 0, quadrics = 0, meshes = 0;
        for (const sg::Shape& shape : scene_.shapes) {
            const sg::GeometryShape& g = scene_.geometries[shape.geometry].shape;
            if (std::holds_alternative<sg::Sphere>(g)) ++spheres;
            else if (std::holds_alternative<sg::Box>(g) || std::holds_alternative<sg::Cylinder>(g) ||
                     std::holds_alternative<sg::Cone>(g))
                ++quadrics;
            else if (!std::holds_alternative<std::monostate>(g)) ++meshes;
        }
        reserve_huge(out_.spheres, spheres);
        reserve_huge(out_.quadrics, quadrics);
        out_.meshes.reserve(meshes);
    }

    // ---- bindable nodes (first pass)

    struct Bindables {
        std::vector<Viewpoint> viewpoints;
        std::optional<Background> background;
        std::optional<Fog> fog;
        std::optional<bool> headlight;
    };
    Bindables main_, inlined_;

    // Marks the groups whose subtree holds a bindable node: an iterative post-order walk over the
    // DAG, as USE chains can nest far deeper than the stack allows.
    void mark_bindables() {
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
                        if (c.kind != sg::NodeKind::Shape && c.kind != sg::NodeKind::Light)
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

    void collect_bindables() {
        mark_bindables();
        collect(Scene::kRoot, Mat4(1.0), false, 0);
    }

    void collect(sg::Index g, const Mat4& parent, bool in_inline, size_t depth) {
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
                    collect(c.index, m, in_inline, depth + 1);
                    break;
                case sg::NodeKind::Viewpoint:
                    b.viewpoints.push_back(make_viewpoint(scene_.viewpoints[c.index], m));
                    break;
                case sg::NodeKind::Background:
                    if (!b.background)
                        b.background = make_background(scene_.backgrounds[c.index], m);
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

    Viewpoint make_viewpoint(const sg::Viewpoint& v, const Mat4& m) {
        Viewpoint out;
        out.def_name = v.def_name;
        out.description = v.description;
        out.ortho = v.ortho;
        const Mat3 linear = linear_part(m);
        out.position = transform_point(m, finite_or(v.position, Vec3(0.0, 0.0, 10.0)));
        out.world_from_camera = orthonormalize(linear) * rotation_matrix(v.orientation);
        out.field_of_view = v.field_of_view;
        if (!(v.field_of_view > 0.0 && v.field_of_view < kPi)) {
            // Every value in (0, pi) is a camera, however narrow (SPEC section 4). Outside, a value
            // of pi or more is taken as the widest sensible view; 0, negative or NaN as the default.
            out.field_of_view = v.field_of_view >= kPi ? kPi - 0.01 : 0.785398;
            NodeReport(diagnostics_, v.origin)
                .warn("field-of-view", "fieldOfView " + format_g(v.field_of_view) +
                                           " lies outside (0, pi); using " +
                                           format_g(out.field_of_view));
        }
        const double s = mean_scale(linear);
        for (int i = 0; i < 4; ++i) out.ortho_extent[i] = v.ortho_extent[i] * s;
        return out;
    }

    Background make_background(const sg::Background& b, const Mat4& m) {
        Background out;
        out.present = true;
        out.world_from_background = orthonormalize(linear_part(m));
        out.sky_colors = b.sky_color;
        out.sky_angles = b.sky_angle;
        out.ground_colors = b.ground_color;
        out.ground_angles = b.ground_angle;
        NodeReport report(diagnostics_, b.origin);
        if (out.sky_colors.empty()) out.sky_colors.push_back(Vec3(0.0));
        if (out.sky_angles.size() + 1 != out.sky_colors.size()) {
            report.warn(
                "angles",
                "skyColor needs one value more than skyAngle; the extra values are ignored");
            const size_t n = std::min(out.sky_angles.size(), out.sky_colors.size() - 1);
            out.sky_angles.resize(n);
            out.sky_colors.resize(n + 1);
        }
        if (!out.ground_colors.empty() &&
            out.ground_angles.size() + 1 != out.ground_colors.size()) {
            report.warn(
                "angles",
                "groundColor needs one value more than groundAngle; the extra values are ignored");
            const size_t n = std::min(out.ground_angles.size(), out.ground_colors.size() - 1);
            out.ground_angles.resize(n);
            out.ground_colors.resize(n + 1);
        }
        for (int face = 0; face < 6; ++face) {
            if (b.urls[face].empty()) continue;
            out.panorama[face] = load_image(b.urls[face], b.from_file, false, false, b.origin);
        }
        return out;
    }

    Fog make_fog(const sg::Fog& f, const Mat4& m) {
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

    void choose_viewer() {
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

    // ---- graph (second pass)

    void visit(sg::Index g, const Mat4& parent, uint32_t light_set, size_t depth) {
        if (stopped_) return;
        const sg::Group& group = scene_.groups[g];
        if (group.singular) return;
        if (depth > options_.max_depth) {
            if (!depth_warned_)
                NodeReport(diagnostics_, group.origin)
                    .warn("depth", "is nested more than " + std::to_string(options_.max_depth) +
                                       " levels deep; skipped");
            depth_warned_ = true;
            return;
        }
        if (++visits_ > options_.max_group_visits) return stop("grouping nodes");
        Mat4 m = group.has_transform() ? parent * scene_.local_from_child(group) : parent;
        if (group.billboard()) {
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
            if (c.kind == sg::NodeKind::Light) {
                const sg::Light& l = scene_.lights[c.index];
                if (!l.on || l.global) continue;
                if (const auto index = add_light(l, m)) scoped_.push_back(*index);
            }
        if (scoped_.size() != scoped_before) light_set = light_set_of(scoped_);

        for (const sg::ChildRef& c : children) {
            switch (c.kind) {
                case sg::NodeKind::Group:
                    visit(c.index, m, light_set, depth + 1);
                    break;
                case sg::NodeKind::Shape:
                    emit_shape(scene_.shapes[c.index], m, light_set);
                    break;
                case sg::NodeKind::Light: {
                    const sg::Light& l = scene_.lights[c.index];
                    if (l.on && l.global)
                        if (const auto index = add_light(l, m)) global_lights_.push_back(*index);
                    break;
                }
                default:
                    break;  // bindable nodes: first pass
            }
        }
        scoped_.resize(scoped_before);
    }

    uint32_t light_set_of(const std::vector<uint32_t>& lights) {
        const auto [it, inserted] =
            light_set_index_.try_emplace(lights, uint32_t(out_.light_sets.size()));
        if (inserted) out_.light_sets.push_back(lights);
        return it->second;
    }

    std::optional<uint32_t> add_light(const sg::Light& l, const Mat4& m) {
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

    // ---- shapes

    void emit_shape(const sg::Shape& shape, const Mat4& m, uint32_t light_set) {
        const sg::Geometry& g = scene_.geometries[shape.geometry];
        if (std::holds_alternative<std::monostate>(g.shape)) {
            ++stats_.skipped_shapes;
            return;
        }
        if (stats_.spheres + stats_.quadrics + stats_.meshes + stats_.instances >= options_.max_primitives)
            return stop("primitives");
        const uint32_t material = material_of(shape, g);
        const uint32_t shading = shading_of(material, light_set);

        if (const auto* s = std::get_if<sg::Sphere>(&g.shape)) {
            const double scale = uniform_scale(linear_part(m));
            if (scale > 0.0) {
                Sphere sphere;
                sphere.center = transform_point(m, Vec3(0.0));
                sphere.radius = s->radius * scale;
                sphere.shading = shading;
                sphere.gas = gas_of(out_.materials[material]);
                out_.spheres.push_back(sphere);
                ++stats_.spheres;
            } else {
                add_quadric(QuadricKind::Ellipsoid, m, Vec3(2.0 * s->radius), shading);
            }
            return;
        }
        if (const auto* b = std::get_if<sg::Box>(&g.shape)) {
            add_quadric(QuadricKind::Box, m, b->size, shading);
            return;
        }
        if (const auto* c = std::get_if<sg::Cylinder>(&g.shape)) {
            Quadric& q = add_quadric(QuadricKind::Cylinder, m,
                                     Vec3(2 * c->radius, c->height, 2 * c->radius), shading);
            q.side = c->side, q.top = c->top, q.bottom = c->bottom;
            return;
        }
        if (const auto* c = std::get_if<sg::Cone>(&g.shape)) {
            Quadric& q =
                add_quadric(QuadricKind::Cone, m,
                            Vec3(2 * c->bottom_radius, c->height, 2 * c->bottom_radius), shading);
            q.side = c->side, q.top = false, q.bottom = c->bottom;
            return;
        }
        const bool want_uvs = out_.materials[material].texture >= 0;
        std::unique_ptr<TriMesh>& cached = mesh_cache_[want_uvs ? 1 : 0][shape.geometry];
        if (!cached)
            cached = std::make_unique<TriMesh>(triangulate_geometry(g, want_uvs, diagnostics_));
        if (recover_spheres_ &&
            std::holds_alternative<std::unique_ptr<sg::IndexedFaceSet>>(g.shape) &&
            recover_exact(shape.geometry, *cached, m, shading, out_.materials[material], want_uvs))
            return;
        if (cached->triangles.empty()) {
            ++stats_.skipped_shapes;
            return;
        }
        if (stats_.triangles + cached->triangle_count() > options_.max_triangles)
            return stop("triangles");
        stats_.triangles += cached->triangle_count();
        if (cached->triangle_count() >= kInstanceMinTriangles) {
            MeshUse& use = mesh_uses_[want_uvs ? 1 : 0][shape.geometry];
            if (use.prototype == kNone && use.first_mesh != kNone) {
                // The second placement: the geometry becomes a prototype, and its first placement, a world
                // mesh until now, an instance (the mesh is emptied here and dropped at the end).
                use.prototype = uint32_t(out_.prototypes.size());
                out_.prototypes.push_back(object_mesh(*cached));
                out_.meshes[use.first_mesh] = Mesh{};
                --stats_.meshes;
                add_instance(use.prototype, use.first_transform, use.first_shading);
            }
            if (use.prototype != kNone) {
                add_instance(use.prototype, m, shading);
                return;
            }
            use.first_mesh = uint32_t(out_.meshes.size());
            use.first_transform = m;
            use.first_shading = shading;
        }
        out_.meshes.push_back(world_mesh(*cached, m, shading));
        ++stats_.meshes;
    }

    // ---- recovery of exact shapes from meshes (FlattenOptions::recover_spheres)

    struct Recovery {
        std::optional<SphereFit> sphere;
        std::optional<CylinderFit> cylinder;
        RecoveryMiss why = RecoveryMiss::OffSurface;
    };

    static Recovery recognise(const TriMesh& mesh) {
        Recovery r;
        if (!mesh.colors.empty()) {
            r.why = RecoveryMiss::Colored;
            return r;
        }
        FitFailure as_sphere = FitFailure::OffSurface, as_cylinder = FitFailure::OffSurface;
        r.sphere = fit_tessellated_sphere(mesh.positions, &mesh.triangles, &as_sphere);
        if (!r.sphere)
            r.cylinder = fit_tessellated_cylinder(mesh.positions, mesh.triangles, &as_cylinder);
        r.why = RecoveryMiss(std::max(as_sphere, as_cylinder));  // the more specific reason
        return r;
    }

    // Emits the exact shape the mesh of `geometry` stands for at this placement, or counts why not.
    bool recover_exact(sg::Index geometry, const TriMesh& mesh, const Mat4& m, uint32_t shading,
                       const Material& material, bool want_uvs) {
        ++stats_.recovery_candidates;
        auto miss = [&](RecoveryMiss why) {
            ++stats_.recovery_misses[size_t(why)];
            return false;
        };
        if (want_uvs) return miss(RecoveryMiss::Textured);
        std::optional<Recovery>& r = recoveries_[geometry];
        if (!r) r = recognise(mesh);
        if (r->cylinder) {
            add_recovered_cylinder(*r->cylinder, m, shading);
            return true;
        }
        if (!r->sphere) return miss(r->why);
        const double scale = uniform_scale(linear_part(m));
        const Mat4 at_center = m * translation_matrix(r->sphere->center);
        if (scale > 0.0) {
            Sphere sphere;
            sphere.center = transform_point(at_center, Vec3(0.0));
            sphere.radius = r->sphere->radius * scale;
            sphere.shading = shading;
            sphere.gas = gas_of(material);
            out_.spheres.push_back(sphere);
            ++stats_.spheres;
            ++stats_.recovered_spheres;
            return true;
        }
        if (gas_of(material)) return miss(RecoveryMiss::NonUniformGas);
        add_quadric(QuadricKind::Ellipsoid, at_center, Vec3(2.0 * r->sphere->radius), shading);
        ++stats_.recovered_ellipsoids;
        return true;
    }

    void add_recovered_cylinder(const CylinderFit& c, const Mat4& m, uint32_t shading) {
        // The Cylinder quadric runs along object y: turn y onto the fitted axis (+y to +axis, so
        // that `top` stays the +axis end) and move it to the fitted centre.
        Mat4 local(1.0);
        if (c.axis == 0)
            local = Mat4(Vec4(0, -1, 0, 0), Vec4(1, 0, 0, 0), Vec4(0, 0, 1, 0), Vec4(0, 0, 0, 1));
        if (c.axis == 2)
            local = Mat4(Vec4(1, 0, 0, 0), Vec4(0, 0, 1, 0), Vec4(0, -1, 0, 0), Vec4(0, 0, 0, 1));
        local[3] = Vec4(c.center, 1.0);
        Quadric& q = add_quadric(QuadricKind::Cylinder, m * local,
                                 Vec3(2.0 * c.radius, c.height, 2.0 * c.radius), shading);
        q.top = c.top, q.bottom = c.bottom;
        ++stats_.recovered_cylinders;
    }

    static Mat4 translation_matrix(const Vec3& t) {
        Mat4 out(1.0);
        out[3] = Vec4(t, 1.0);
        return out;
    }

    void add_instance(uint32_t prototype, const Mat4& m, uint32_t shading) {
        MeshInstance in;
        in.prototype = prototype;
        in.world_from_object = m;
        in.object_from_world = glm::inverse(m);
        in.shading = shading;
        out_.instances.push_back(in);
        ++stats_.instances;
    }

    static Mesh object_mesh(const TriMesh& t) {
        Mesh mesh;
        mesh.solid = t.solid;
        mesh.positions = t.positions;
        mesh.triangles = t.triangles;
        mesh.normals = t.normals;
        mesh.uvs = t.uvs;
        mesh.colors = t.colors;
        return mesh;
    }

    Quadric& add_quadric(QuadricKind kind, const Mat4& m, const Vec3& size, uint32_t shading) {
        Quadric q;
        q.kind = kind;
        q.world_from_object = m;
        q.object_from_world = glm::inverse(m);
        q.size = size;
        q.shading = shading;
        out_.quadrics.push_back(q);
        ++stats_.quadrics;
        return out_.quadrics.back();
    }

    static Mesh world_mesh(const TriMesh& t, const Mat4& m, uint32_t shading) {
        Mesh mesh = object_mesh(t);
        mesh.shading = shading;
        for (Vec3& p : mesh.positions) p = transform_point(m, p);
        const Mat3 linear = linear_part(m);
        if (!mesh.normals.empty()) {
            const Mat3 normal_from_object = glm::transpose(glm::inverse(linear));
            for (Vec3& normal : mesh.normals) normal = map_normal(normal_from_object, normal);
        }
        if (glm::determinant(linear) < 0.0) {
            // A mirror turns counter-clockwise into clockwise: swap two corners to keep the front
            // side.
            for (size_t c = 0; c + 2 < mesh.triangles.size(); c += 3) {
                std::swap(mesh.triangles[c + 1], mesh.triangles[c + 2]);
                if (!mesh.normals.empty()) std::swap(mesh.normals[c + 1], mesh.normals[c + 2]);
                if (!mesh.uvs.empty()) std::swap(mesh.uvs[c + 1], mesh.uvs[c + 2]);
                if (!mesh.colors.empty()) std::swap(mesh.colors[c + 1], mesh.colors[c + 2]);
            }
        }
        return mesh;
    }

    void stop(const char* what) {
        if (!stopped_)
            diagnostics_.error(
                SourceLoc{},
                std::string("the scene expands to more ") + what +
                    " than the limit allows (DEF/USE instancing); the rest is not rendered");
        stopped_ = true;
    }

    bool gas_of(const Material& m) const {
        if (m.sphere_mode >= 0) return m.sphere_mode == int8_t(SphereMode::Gas);
        return options_.spheres == SpheresOption::Gas;
    }

    // ---- materials

    uint32_t material_of(const sg::Shape& shape, const sg::Geometry& g) {
        const bool plain = shape.hints == sg::kNone && g.hints == sg::kNone;
        const size_t slot =
            shape.appearance == sg::kNone ? scene_.appearances.size() : shape.appearance;
        if (plain && appearance_material_[slot] >= 0) return uint32_t(appearance_material_[slot]);
        const uint32_t index = intern_material(resolve_material(shape, g));
        if (plain) appearance_material_[slot] = int32_t(index);
        return index;
    }

    uint32_t intern_material(const Material& m) {
        const auto [it, inserted] =
            material_index_.try_emplace(key_of(m), uint32_t(out_.materials.size()));
        if (inserted) out_.materials.push_back(m);
        return it->second;
    }

    uint32_t shading_of(uint32_t material, uint32_t light_set) {
        const uint64_t key = (uint64_t(material) << 32) | light_set;
        const auto [it, inserted] = shading_index_.try_emplace(key, uint32_t(out_.shadings.size()));
        if (inserted) out_.shadings.push_back(Shading{material, light_set});
        return it->second;
    }

    Material resolve_material(const sg::Shape& shape, const sg::Geometry& g) {
        Material out;
        sg::Hints hints;
        const sg::Appearance* app =
            shape.appearance == sg::kNone ? nullptr : &scene_.appearances[shape.appearance];
        if (app && app->texture != sg::kNone) out.texture = texture_of(app->texture);
        if (app && app->has_texture_transform) {
            const sg::TextureTransform& t = app->texture_transform;
            out.texture_transform =
                texture_transform_matrix(t.center, t.rotation, t.scale, t.translation);
        }
        if (!app || app->material == sg::kNone) {
            out.lit = false;
        } else {
            const sg::Material& m = scene_.materials[app->material];
            hints = scene_.hints_of(m.hints);
            NodeReport report(diagnostics_, m.origin);
            auto colour = [&](const Vec3& c, const Vec3& fallback) {
                if (std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z))
                    return glm::clamp(c, 0.0, 1.0);
                report.warn("non-finite", "has a NaN or infinite colour; using the default");
                return fallback;
            };
            auto unit = [&](double d, double fallback) {
                if (std::isfinite(d)) return std::clamp(d, 0.0, 1.0);
                report.warn("non-finite", "has a NaN or infinite value; using the default");
                return fallback;
            };
            out.diffuse = colour(m.diffuse_color, Vec3(0.8));
            out.specular = colour(m.specular_color, Vec3(0.0));
            out.emissive = colour(m.emissive_color, Vec3(0.0));
            out.ambient_intensity = unit(m.ambient_intensity, 0.2);
            out.shininess = unit(m.shininess, 0.2);
            out.transparency = unit(m.transparency, 0.0);
            if (m.model == sg::MaterialModel::Physical) {
                out.specular = Vec3(0.0);
                out.reflectivity = unit(m.metallic, 0.0) * (1.0 - unit(m.roughness, 1.0));
            } else if (m.model == sg::MaterialModel::Unlit) {
                out.diffuse = out.specular = Vec3(0.0);
                out.ambient_intensity = 0.0;
                if (out.texture >= 0) out.lit = false;
            }
        }
        hints.override_with(scene_.hints_of(shape.hints));
        hints.override_with(scene_.hints_of(g.hints));
        if (hints.reflectivity >= 0.0) out.reflectivity = hints.reflectivity;
        if (hints.ior >= 0.0) out.ior = hints.ior;
        if (hints.sphere_mode != sg::SphereHint::Unset)
            out.sphere_mode = int8_t(hints.sphere_mode == sg::SphereHint::Gas ? SphereMode::Gas
                                                                              : SphereMode::Opaque);
        out.density = hints.density >= 0.0 ? hints.density : options_.density;
        out.albedo = hints.albedo.x >= 0.0 ? hints.albedo : options_.albedo ? *options_.albedo : out.diffuse;
        out.emission = hints.emission.x >= 0.0 ? hints.emission : options_.emission ? *options_.emission : out.emissive;
        return out;
    }

    // ---- textures

    int32_t texture_of(sg::Index t) {
        if (texture_index_[t] != kUnloaded) return texture_index_[t];
        const sg::Texture& tex = scene_.textures[t];
        int32_t index = -1;
        if (tex.kind == sg::TextureKind::Pixel) {
            Texture out;
            out.width = tex.width;
            out.height = tex.height;
            out.channels = tex.components;
            out.repeat_s = tex.repeat_s;
            out.repeat_t = tex.repeat_t;
            out.texels.resize(size_t(tex.width) * tex.height * tex.components);
            for (size_t p = 0; p < tex.pixels.size(); ++p)
                for (int c = 0; c < tex.components; ++c) {
                    // Packed high byte first: 0xRRGGBB, 0xIIAA, ...
                    const int shift = 8 * (tex.components - 1 - c);
                    out.texels[p * tex.components + c] =
                        float((tex.pixels[p] >> shift) & 0xFFu) / 255.0f;
                }
            out_.textures.push_back(std::move(out));
            index = int32_t(out_.textures.size() - 1);
        } else {
            index = load_image(tex.urls, tex.from_file, tex.repeat_s, tex.repeat_t, tex.origin);
        }
        texture_index_[t] = index;
        return index;
    }

    int32_t load_image(const std::vector<std::string>& urls, const std::filesystem::path& from_file,
                       bool repeat_s, bool repeat_t, const sg::Origin& origin) {
        std::vector<std::filesystem::path> roots = options_.allowed_roots;
        if (roots.empty()) roots = scene_.allowed_roots;
        std::filesystem::path from = from_file;
        if (from.empty())
            from = options_.scene_file.empty() ? scene_.main_file : options_.scene_file;
        UrlFailures failures;
        for (const std::string& url : urls) {
            const std::filesystem::path path = resolve_or_note(url, from, roots, failures, true);
            if (path.empty()) continue;
            const std::string key =
                path.string() + (repeat_s ? "|S" : "|s") + (repeat_t ? "T" : "t");
            if (const auto it = image_index_.find(key); it != image_index_.end()) return it->second;
            ImageData image;
            std::string error;
            if (!read_image_file(path, image, error, options_.max_texture_pixels)) {
                failures.add(url + ": " + error);
                continue;
            }
            Texture out;
            out.width = image.width;
            out.height = image.height;
            out.channels = image.channels;
            out.texels = std::move(image.texels);
            out.repeat_s = repeat_s;
            out.repeat_t = repeat_t;
            out_.textures.push_back(std::move(out));
            const int32_t index = int32_t(out_.textures.size() - 1);
            image_index_[key] = index;
            return index;
        }
        NodeReport(diagnostics_, origin)
            .warn("texture", "no texture image could be loaded (" + failures.reasons + "); untextured");
        return -1;
    }

    const Scene& scene_;
    const FlattenOptions& options_;
    Diagnostics& diagnostics_;
    FlattenStats& stats_;
    FlatScene out_;

    Vec3 viewer_position_{0.0, 0.0, 10.0};
    Vec3 viewer_up_{0.0, 1.0, 0.0};
    Vec3 viewer_back_{0.0, 0.0, 1.0};
    std::vector<uint8_t> has_bindable_;  // per group
    size_t collect_visits_ = 0;
    std::vector<uint32_t> scoped_;  // scoped lights in effect along the current path
    std::vector<uint32_t> global_lights_;
    std::map<std::vector<uint32_t>, uint32_t> light_set_index_;
    std::unordered_map<MaterialKey, uint32_t, MaterialKeyHash, MaterialKeyEqual> material_index_;
    std::vector<int32_t> appearance_material_;  // per appearance (+1: none) without extra hints
    std::unordered_map<uint64_t, uint32_t> shading_index_;
    std::vector<int32_t> texture_index_;
    std::unordered_map<std::string, int32_t> image_index_;
    std::vector<std::unique_ptr<TriMesh>>
        mesh_cache_[2];  // per geometry, without / with texture coordinates
    // A mesh placed twice or more is instanced from then on when it has at least this many triangles:
    // an instance costs about 300 bytes (two matrices, a BVH entry) and a change of coordinates per ray
    // that reaches it, a world copy 84 bytes a triangle in the flat scene and 72 more in the tracer.
    static constexpr size_t kInstanceMinTriangles = 16;
    static constexpr uint32_t kNone = UINT32_MAX;
    struct MeshUse {
        uint32_t first_mesh = kNone;  // index in out_.meshes of the first placement, while it is a world mesh
        uint32_t prototype = kNone;   // set from the second placement on
        Mat4 first_transform{1.0};
        uint32_t first_shading = 0;
    };
    std::vector<MeshUse> mesh_uses_[2];  // per geometry, like mesh_cache_
    // Per geometry: unset until tried, then the exact shape its mesh stands for (or why none).
    std::vector<std::optional<Recovery>> recoveries_;
    bool recover_spheres_ = false;
    bool stopped_ = false;
    bool depth_warned_ = false;
    size_t visits_ = 0;
};

}  // namespace

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
    Flattener flattener(scene, options, diagnostics, stats);
    return flattener.run();
}

}  // namespace vr
