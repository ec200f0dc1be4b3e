// Shapes and instances: spheres, quadrics, world meshes, mesh prototypes placed as instances, and
// the exact shapes recovered from tessellated meshes.
#include <algorithm>
#include <cmath>

#include "flatten/flattener.h"
#include "scene/transform.h"

namespace vr::flatten_detail {

void Flattener::emit_shape(const sg::Shape& shape, const Mat4& m, uint32_t light_set) {
    const sg::Geometry& g = scene_.geometries[shape.geometry];
    if (std::holds_alternative<std::monostate>(g.shape)) {
        ++stats_.skipped_shapes;
        return;
    }
    if (stats_.spheres + stats_.quadrics + stats_.meshes + stats_.instances >=
        options_.max_primitives)
        return stop("primitives");
    const uint32_t material = material_of(shape, g);
    if (std::holds_alternative<std::unique_ptr<sg::LineSet>>(g.shape))
        return add_lines(g, shape, m, material);
    // Back faces are culled for opaque surfaces only: a see-through or refracting one needs its
    // far side (docs/rendering.md, Back faces).
    const uint32_t shading = shading_of(
        material, light_set, g.cull_back_faces && out_.materials[material].transparency == 0.0);
    if (pressed_flat_) return emit_pressed_flat(shape, g, m, shading, material);

    if (const auto* s = std::get_if<sg::Sphere>(&g.shape)) {
        const double scale = uniform_scale(linear_part(m));
        // VRML97 6.42 maps a Sphere's texture in its own coordinate system: a textured sphere
        // that its transforms turn stays analytic as an ellipsoid quadric, whose object space
        // the texture lookup uses (an untextured one looks the same either way).
        const bool turned_texture =
            out_.materials[material].texture >= 0 && !is_scaled_identity(linear_part(m));
        if (scale > 0.0 && !turned_texture) {
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
    // Every triangle mesh is a candidate: Jmol's IndexedFaceSets, ChimeraX's IndexedTriangleSets,
    // TriangleSets and the other composed sets alike (docs/rendering.md "Recovered spheres and
    // cylinders").
    const bool mesh = std::holds_alternative<std::unique_ptr<sg::IndexedFaceSet>>(g.shape) ||
                      std::holds_alternative<std::unique_ptr<sg::ComposedSet>>(g.shape);
    if (recover_spheres_ && mesh &&
        recover_exact(shape.geometry, *cached, m, shading, out_.materials[material], want_uvs))
        return;
    if (cached->triangles.empty()) {
        ++stats_.skipped_shapes;
        return;
    }
    if (stats_.triangles + cached->triangle_count() > options_.max_triangles)
        return stop("triangles");
    stats_.triangles += cached->triangle_count();
    // A mesh under a ClipPlane stays in world space: the tracer clips world hits only.
    if (cached->triangle_count() >= kInstanceMinTriangles && !clipped()) {
        MeshUse& use = mesh_uses_[want_uvs ? 1 : 0][shape.geometry];
        if (use.prototype == kNone && use.first_mesh != kNone) {
            // The second placement: the geometry becomes a prototype, and its first placement, a
            // world mesh until now, an instance (the mesh is emptied here and dropped at the end).
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

void Flattener::add_lines(const sg::Geometry& g, const sg::Shape& shape, const Mat4& m,
                          uint32_t material) {
    NodeReport report(diagnostics_, g.origin);
    const Polylines p = line_geometry(*std::get<std::unique_ptr<sg::LineSet>>(g.shape), report);
    // Unlit marks (X3D 11.2.3): the Color node's colours, else the Material's emissiveColor, else
    // white when the Appearance has no Material.
    const sg::Appearance* app =
        shape.appearance == sg::kNone ? nullptr : &scene_.appearances[shape.appearance];
    const Vec3 plain =
        app && app->material != sg::kNone ? out_.materials[material].emissive : Vec3(1.0);
    // Opacity by the rules of surfaces: a ColorRGBA's alpha, else 1 - Material.transparency.
    const double plain_alpha =
        app && app->material != sg::kNone ? 1.0 - out_.materials[material].transparency : 1.0;
    auto color = [&](size_t i) { return p.colors.empty() ? plain : p.colors[i]; };
    auto alpha = [&](size_t i) {
        const double a = p.alphas.empty() ? plain_alpha : p.alphas[i];
        return std::isfinite(a) ? std::clamp(a, 0.0, 1.0) : 1.0;
    };
    auto world = [&](size_t i) { return transform_point(m, p.positions[i]); };
    if (p.points) {
        for (size_t i = 0; i < p.positions.size(); ++i)
            out_.points.push_back({world(i), color(i), alpha(i)});
        return;
    }
    for (size_t k = 0; k < p.starts.size(); ++k) {
        const size_t end = k + 1 < p.starts.size() ? p.starts[k + 1] : p.positions.size();
        for (size_t i = p.starts[k]; i + 1 < end; ++i)
            out_.segments.push_back(
                {world(i), world(i + 1), color(i), color(i + 1), alpha(i), alpha(i + 1)});
    }
}

Flattener::Recovery Flattener::recognise(const TriMesh& mesh) {
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

bool Flattener::recover_exact(sg::Index geometry, const TriMesh& mesh, const Mat4& m,
                              uint32_t shading, const Material& material, bool want_uvs) {
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

void Flattener::add_recovered_cylinder(const CylinderFit& c, const Mat4& m, uint32_t shading) {
    // The Cylinder quadric runs along object y: turn y onto the fitted axis (+y to +axis, so
    // that `top` stays the +axis end) and move it to the fitted centre. An oblique one is turned
    // by the axis and angle `convert` writes (compact_scene.cpp), through the Transform's own
    // arithmetic, so that the converted file places the same matrix.
    Mat4 local(1.0);
    if (c.axis == 0)
        local = Mat4(Vec4(0, -1, 0, 0), Vec4(1, 0, 0, 0), Vec4(0, 0, 1, 0), Vec4(0, 0, 0, 1));
    if (c.axis == 2)
        local = Mat4(Vec4(1, 0, 0, 0), Vec4(0, 0, 1, 0), Vec4(0, -1, 0, 0), Vec4(0, 0, 0, 1));
    local[3] = Vec4(c.center, 1.0);
    if (c.axis < 0) {
        TransformFields placed;
        placed.translation = c.center;
        placed.rotation = rotation_onto_direction(c);
        local = transform_matrix(placed);
    }
    Quadric& q = add_quadric(QuadricKind::Cylinder, m * local,
                             Vec3(2.0 * c.radius, c.height, 2.0 * c.radius), shading);
    q.top = c.top, q.bottom = c.bottom;
    ++stats_.recovered_cylinders;
}

void Flattener::emit_pressed_flat(const sg::Shape& shape, const sg::Geometry& g, const Mat4& m,
                                  uint32_t shading, uint32_t material) {
    // No inverse exists: no sphere, quadric or instance (each keeps object_from_world), so only
    // meshes, in world space, with their flat faces' own normals (the vertex normals of a pressed
    // surface all point along the plane's normal or vanish). The build warned once for the group.
    if (std::holds_alternative<sg::Sphere>(g.shape) || std::holds_alternative<sg::Box>(g.shape) ||
        std::holds_alternative<sg::Cylinder>(g.shape) ||
        std::holds_alternative<sg::Cone>(g.shape)) {
        ++stats_.skipped_shapes;
        return;
    }
    const bool want_uvs = out_.materials[material].texture >= 0;
    std::unique_ptr<TriMesh>& cached = mesh_cache_[want_uvs ? 1 : 0][shape.geometry];
    if (!cached)
        cached = std::make_unique<TriMesh>(triangulate_geometry(g, want_uvs, diagnostics_));
    if (cached->triangles.empty()) {
        ++stats_.skipped_shapes;
        return;
    }
    if (stats_.triangles + cached->triangle_count() > options_.max_triangles)
        return stop("triangles");
    stats_.triangles += cached->triangle_count();
    Mesh mesh = object_mesh(*cached);
    mesh.shading = shading;
    mesh.normals.clear();
    for (Vec3& p : mesh.positions) p = transform_point(m, p);
    out_.meshes.push_back(std::move(mesh));
    ++stats_.meshes;
}

Mat4 Flattener::translation_matrix(const Vec3& t) {
    Mat4 out(1.0);
    out[3] = Vec4(t, 1.0);
    return out;
}

void Flattener::add_instance(uint32_t prototype, const Mat4& m, uint32_t shading) {
    MeshInstance in;
    in.prototype = prototype;
    in.world_from_object = m;
    in.object_from_world = glm::inverse(m);
    in.shading = shading;
    out_.instances.push_back(in);
    ++stats_.instances;
}

Mesh Flattener::object_mesh(const TriMesh& t) {
    Mesh mesh;
    mesh.solid = t.solid;
    mesh.positions = t.positions;
    mesh.triangles = t.triangles;
    mesh.normals = t.normals;
    mesh.uvs = t.uvs;
    mesh.colors = t.colors;
    mesh.alphas = t.alphas;
    mesh.fog_depths = t.fog_depths;
    return mesh;
}

Quadric& Flattener::add_quadric(QuadricKind kind, const Mat4& m, const Vec3& size,
                                uint32_t shading) {
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

Mesh Flattener::world_mesh(const TriMesh& t, const Mat4& m, uint32_t shading) {
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
            if (!mesh.alphas.empty()) std::swap(mesh.alphas[c + 1], mesh.alphas[c + 2]);
            if (!mesh.fog_depths.empty()) std::swap(mesh.fog_depths[c + 1], mesh.fog_depths[c + 2]);
        }
    }
    return mesh;
}

}  // namespace vr::flatten_detail
