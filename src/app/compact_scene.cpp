#include "app/compact_scene.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "geometry/cylinder_fit.h"
#include "geometry/sphere_fit.h"
#include "parser/registry.h"

namespace vr {

namespace {

// Nodes whose identity matters beyond their value: events reach them by ROUTE or through a PROTO
// interface, or another file imports them.
std::unordered_set<NodeId> named_by_events(const NodeTree& tree) {
    std::unordered_set<NodeId> out;
    for (const Route& r : tree.routes) out.insert({r.from, r.to});
    for (const IsLink& l : tree.is_links) out.insert({l.instance, l.node});
    for (const Export& e : tree.exports) out.insert(e.node);
    for (const Import& i : tree.imports) out.insert(i.node);
    return out;
}

// Every reference to a key of `to` (in node fields and among the roots) made to its value.
void replace_references(NodeTree& tree, const std::unordered_map<NodeId, NodeId>& to) {
    if (to.empty()) return;
    for (NodeId& ref : tree.node_refs)
        if (auto it = to.find(ref); it != to.end()) ref = it->second;
    for (NodeId& ref : tree.roots)
        if (auto it = to.find(ref); it != to.end()) ref = it->second;
}

// A field of a node being made: numbers, or node references.
struct NewField {
    std::string_view name;
    std::vector<double> numbers;
    std::vector<NodeId> nodes;
};

// Appends a node of type `type` in the table of `spec` with the given fields (those the table does
// not have are left out); kNullNode when the table has no such node.
NodeId add_node(NodeTree& tree, Spec spec, std::string_view type,
                const std::vector<NewField>& fields) {
    const NodeTypeDecl* decl = Registry::builtin().lookup(spec, intern(type));
    if (!decl) return kNullNode;
    Node n;
    n.kind = tree.kind_of(decl, decl->name);
    n.first_field = static_cast<uint32_t>(tree.fields.size());
    uint32_t count = 0;
    for (const NewField& f : fields) {
        const FieldDecl* fd = decl->find(f.name);
        if (!fd) continue;
        FieldEntry e;
        e.name = fd->name;
        e.type = fd->type;
        if (fd->type.kind == ValueKind::Node) {
            e.begin = static_cast<uint32_t>(tree.node_refs.size());
            for (NodeId id : f.nodes) tree.node_refs.push_back(id);
            e.count = static_cast<uint32_t>(f.nodes.size());
        } else {
            e.begin = static_cast<uint32_t>(tree.numbers.size());
            for (double v : f.numbers) tree.numbers.push_back(v);
            e.count = static_cast<uint32_t>(f.numbers.size());
        }
        tree.fields.push_back(e);
        ++count;
    }
    return tree.add_node(n, count);
}

// The vertices and triangles of a mesh node as the recognisers take them: IndexedFaceSet faces
// as fans, IndexedTriangleSet index triples, TriangleSet vertex triples. Nothing when an index is
// out of range or there is no Coordinate.
struct MeshPoints {
    std::vector<Vec3> points;
    std::vector<uint32_t> triangles;
};
std::optional<MeshPoints> mesh_points(const NodeTree& tree, NodeId mesh) {
    const FieldView coord = tree.get(mesh, intern("coord"));
    if (coord.nodes.empty() || coord.nodes[0] == kNullNode) return std::nullopt;
    // GeoCoordinate points are latitudes and longitudes, not the mesh's own space.
    const std::string_view coord_type = tree.type_name(coord.nodes[0]);
    if (coord_type != "Coordinate" && coord_type != "CoordinateDouble") return std::nullopt;
    const FieldView point = tree.get(coord.nodes[0], intern("point"));
    MeshPoints m;
    for (size_t i = 0; i + 2 < point.numbers.size(); i += 3)
        m.points.emplace_back(point.numbers[i], point.numbers[i + 1], point.numbers[i + 2]);
    const size_t n = m.points.size();
    const std::string_view type = tree.type_name(mesh);
    if (type == "TriangleSet") {
        for (size_t i = 0; i + 2 < n; i += 3)
            m.triangles.insert(m.triangles.end(), {uint32_t(i), uint32_t(i + 1), uint32_t(i + 2)});
        return m;
    }
    const FieldView index =
        tree.get(mesh, type == "IndexedFaceSet" ? intern("coordIndex") : intern("index"));
    auto valid = [&](double v) { return v >= 0.0 && v < double(n); };
    if (type == "IndexedTriangleSet") {
        for (size_t i = 0; i + 2 < index.numbers.size(); i += 3) {
            if (!valid(index.numbers[i]) || !valid(index.numbers[i + 1]) ||
                !valid(index.numbers[i + 2]))
                return std::nullopt;
            m.triangles.insert(m.triangles.end(),
                               {uint32_t(index.numbers[i]), uint32_t(index.numbers[i + 1]),
                                uint32_t(index.numbers[i + 2])});
        }
        return m;
    }
    std::vector<uint32_t> face;
    auto close_face = [&] {
        for (size_t k = 2; k < face.size(); ++k)
            m.triangles.insert(m.triangles.end(), {face[0], face[k - 1], face[k]});
        face.clear();
    };
    for (double v : index.numbers) {
        if (v < 0.0) {
            close_face();
            continue;
        }
        if (!valid(v)) return std::nullopt;
        face.push_back(uint32_t(v));
    }
    close_face();
    return m;
}

// What the mesh is, or why it is not: the renderer's order (flatten/shapes.cpp, recognise):
// a sphere, else a cylinder, the more specific of the two reasons.
struct Recognised {
    std::optional<SphereFit> sphere;
    std::optional<CylinderFit> cylinder;
    RecoveryMiss why = RecoveryMiss::OffSurface;
};
Recognised recognise(const MeshPoints& m) {
    Recognised r;
    FitFailure as_sphere = FitFailure::OffSurface, as_cylinder = FitFailure::OffSurface;
    r.sphere = fit_tessellated_sphere(m.points, &m.triangles, &as_sphere);
    if (!r.sphere) r.cylinder = fit_tessellated_cylinder(m.points, m.triangles, &as_cylinder);
    r.why = RecoveryMiss(std::max(as_sphere, as_cylinder));
    return r;
}

// The Shapes holding each mesh, and whether any of them is textured.
struct MeshUses {
    std::vector<NodeId> shapes;
    bool textured = false;
};
std::unordered_map<NodeId, MeshUses> mesh_uses(const NodeTree& tree) {
    std::unordered_map<NodeId, MeshUses> out;
    for (NodeId id = 0; id < tree.nodes.size(); ++id) {
        if (tree.type_name(id) != "Shape") continue;
        const NodeId geometry = tree.get_node(id, intern("geometry"));
        if (geometry == kNullNode) continue;
        MeshUses& u = out[geometry];
        u.shapes.push_back(id);
        const NodeId appearance = tree.get_node(id, intern("appearance"));
        if (appearance != kNullNode && tree.type_name(appearance) == "Appearance" &&
            tree.get_node(appearance, intern("texture")) != kNullNode)
            u.textured = true;
    }
    return out;
}

// The exact node for a recognised mesh, in object space of the mesh, and the placement it needs
// (identity when the shape is centred on the origin and, for a cylinder, along y).
struct ExactNode {
    NodeId node = kNullNode;
    Vec3 translation{0.0};
    std::array<double, 4> rotation{0.0, 0.0, 1.0, 0.0};
    bool placed = false;
};
ExactNode exact_node(NodeTree& tree, NodeId mesh, const Recognised& r) {
    const Spec spec = tree.decl(mesh)->spec;
    // X3D's solid: the mesh's own, so that back faces are drawn (or not) as before.
    const double solid = tree.get_bool(mesh, intern("solid")) ? 1.0 : 0.0;
    ExactNode out;
    if (r.sphere) {
        out.node = add_node(tree, spec, "Sphere",
                            {{"radius", {r.sphere->radius}, {}}, {"solid", {solid}, {}}});
        out.translation = r.sphere->center;
    } else {
        const CylinderFit& c = *r.cylinder;
        out.node = add_node(tree, spec, "Cylinder",
                            {{"radius", {c.radius}, {}},
                             {"height", {c.height}, {}},
                             {"top", {c.top ? 1.0 : 0.0}, {}},
                             {"bottom", {c.bottom ? 1.0 : 0.0}, {}},
                             {"solid", {solid}, {}}});
        out.translation = c.center;
        // The Cylinder runs along y: turned onto the fitted axis, +y to +axis (as the renderer's
        // recovery turns it: flatten/shapes.cpp, add_recovered_cylinder).
        if (c.axis == 0) out.rotation = {0.0, 0.0, 1.0, -kPi / 2.0};
        if (c.axis == 2) out.rotation = {1.0, 0.0, 0.0, kPi / 2.0};
        if (c.axis < 0) {
            const Vec4 turn = rotation_onto_direction(c);
            out.rotation = {turn.x, turn.y, turn.z, turn.w};
        }
    }
    out.placed = out.translation != Vec3(0.0) || out.rotation[3] != 0.0;
    return out;
}

// A Transform placing a copy of `shape` whose geometry is `exact`.
NodeId placed_shape(NodeTree& tree, NodeId shape, const ExactNode& exact) {
    const Spec spec = tree.decl(shape)->spec;
    std::vector<NewField> fields;
    for (const FieldEntry& e : tree.set_fields(shape)) {
        if (e.type.kind != ValueKind::Node || e.name == intern("geometry")) continue;
        NewField f{name_text(e.name), {}, {}};
        for (uint32_t i = 0; i < e.count; ++i) f.nodes.push_back(tree.node_refs[e.begin + i]);
        fields.push_back(std::move(f));
    }
    fields.push_back({"geometry", {}, {exact.node}});
    const NodeId copy = add_node(tree, spec, "Shape", fields);
    const Vec3& t = exact.translation;
    return add_node(tree, spec, "Transform",
                    {{"translation", {t.x, t.y, t.z}, {}},
                     {"rotation",
                      {exact.rotation[0], exact.rotation[1], exact.rotation[2], exact.rotation[3]},
                      {}},
                     {"children", {}, {copy}}});
}

}  // namespace

void recover_exact_nodes(NodeTree& tree, CompactStats& stats) {
    const std::unordered_set<NodeId> fixed = named_by_events(tree);
    const std::unordered_map<NodeId, MeshUses> uses = mesh_uses(tree);
    std::unordered_map<NodeId, NodeId> to;
    const size_t original_nodes = tree.nodes.size();
    for (NodeId mesh = 0; mesh < original_nodes; ++mesh) {
        const std::string_view type = tree.type_name(mesh);
        if (type != "IndexedFaceSet" && type != "IndexedTriangleSet" && type != "TriangleSet")
            continue;
        const auto use = uses.find(mesh);
        if (use == uses.end()) continue;  // not drawn by any Shape
        ++stats.meshes;
        auto miss = [&](RecoveryMiss why) { ++stats.misses[size_t(why)]; };
        if (use->second.textured) {
            miss(RecoveryMiss::Textured);
            continue;
        }
        if (tree.get_node(mesh, intern("color")) != kNullNode) {
            miss(RecoveryMiss::Colored);
            continue;
        }
        bool shapes_fixed = fixed.count(mesh) > 0;
        for (NodeId s : use->second.shapes) shapes_fixed = shapes_fixed || fixed.count(s) > 0;
        const std::optional<MeshPoints> points = mesh_points(tree, mesh);
        if (shapes_fixed || !points) {
            miss(RecoveryMiss::OffSurface);
            continue;
        }
        const Recognised r = recognise(*points);
        if (!r.sphere && !r.cylinder) {
            miss(r.why);
            continue;
        }
        const ExactNode exact = exact_node(tree, mesh, r);
        if (exact.node == kNullNode) {
            miss(RecoveryMiss::OffSurface);
            continue;
        }
        ++(r.sphere ? stats.spheres : stats.cylinders);
        if (!exact.placed) {
            to[mesh] = exact.node;
            continue;
        }
        for (NodeId s : use->second.shapes) to[s] = placed_shape(tree, s, exact);
    }
    replace_references(tree, to);
}

namespace {

// A node's value as text: its type and its set fields, sorted by name, with every number's bits,
// every string and every referenced node's id. Equal keys: nodes no one can tell apart.
std::string value_key(const NodeTree& tree, NodeId id) {
    std::vector<const FieldEntry*> fields;
    for (const FieldEntry& e : tree.set_fields(id)) fields.push_back(&e);
    std::sort(fields.begin(), fields.end(), [](const FieldEntry* a, const FieldEntry* b) {
        return name_text(a->name) < name_text(b->name);
    });
    std::string key(tree.type_name(id));
    auto append = [&key](const void* bytes, size_t n) {
        key.append(static_cast<const char*>(bytes), n);
    };
    for (const FieldEntry* e : fields) {
        key += '\0';
        key += name_text(e->name);
        key += '\0';
        key += char(e->type.kind);
        const FieldView v = tree.view(*e);
        for (double x : v.numbers) {
            const uint64_t bits = std::bit_cast<uint64_t>(x + 0.0);  // -0 and 0 alike
            append(&bits, sizeof bits);
        }
        for (const std::string& s : v.strings) {
            const uint64_t size = s.size();
            append(&size, sizeof size);
            key += s;
        }
        for (NodeId n : v.nodes) append(&n, sizeof n);
    }
    return key;
}

// The nodes reached from the roots (what the writers write).
std::vector<uint8_t> reachable(const NodeTree& tree) {
    std::vector<uint8_t> seen(tree.nodes.size());
    std::vector<NodeId> stack(tree.roots.begin(), tree.roots.end());
    while (!stack.empty()) {
        const NodeId id = stack.back();
        stack.pop_back();
        if (id == kNullNode || seen[id]) continue;
        seen[id] = 1;
        for (const FieldEntry& e : tree.set_fields(id))
            if (e.type.kind == ValueKind::Node)
                for (uint32_t i = 0; i < e.count; ++i) stack.push_back(tree.node_refs[e.begin + i]);
    }
    return seen;
}

}  // namespace

void share_identical_nodes(NodeTree& tree, CompactStats& stats) {
    const std::unordered_set<NodeId> fixed = named_by_events(tree);
    const std::vector<uint8_t> written = reachable(tree);
    // Leaves first, so that the nodes holding them compare equal once their children are one.
    const std::vector<std::vector<std::string_view>> passes = {
        {"Material", "TwoSidedMaterial", "Sphere", "Cylinder", "Cone", "Box"},
        {"Appearance"},
        {"Shape"}};
    for (const std::vector<std::string_view>& types : passes) {
        std::unordered_map<std::string, NodeId> first;
        std::unordered_map<NodeId, NodeId> to;
        for (NodeId id = 0; id < tree.nodes.size(); ++id) {
            const std::string_view type = tree.type_name(id);
            if (!written[id] || fixed.count(id) ||
                std::find(types.begin(), types.end(), type) == types.end())
                continue;
            const auto [it, added] = first.emplace(value_key(tree, id), id);
            if (!added) to[id] = it->second;
        }
        stats.shared += to.size();
        replace_references(tree, to);
    }
}

}  // namespace vr
