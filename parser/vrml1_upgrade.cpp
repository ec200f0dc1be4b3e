// The VRML 1.0 traversal: grouping nodes, the transformation, lights, cameras and inlines. Shapes
// and their appearance are in vrml1_shapes.cpp.
#include "parser/vrml1_upgrade.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "parser/field_value.h"
#include "parser/registry.h"

namespace vr::vrml1 {

namespace {

enum class Kind : uint8_t {
    Separator,
    Group,
    TransformSeparator,
    Switch,
    LOD,
    Anchor,
    Inline,
    Material,
    MaterialBinding,
    NormalBinding,
    Coordinate3,
    Normal,
    TextureCoordinate2,
    Texture2,
    Texture2Transform,
    ShapeHints,
    Translation,
    Rotation,
    Scale,
    Transform,
    MatrixTransform,
    Sphere,
    Cube,
    Cylinder,
    Cone,
    IndexedFaceSet,
    IndexedLineSet,
    PointSet,
    AsciiText,
    FontStyle,
    DirectionalLight,
    PointLight,
    SpotLight,
    PerspectiveCamera,
    OrthographicCamera,
    Silent,
};

// The roles of grammar/vrml1.nodes ("Name : Role {") as the upgrade's kinds.
constexpr std::pair<const char*, Kind> kRoles[] = {
    {"Separator", Kind::Separator},
    {"Group", Kind::Group},
    {"TransformSeparator", Kind::TransformSeparator},
    {"Switch", Kind::Switch},
    {"LOD", Kind::LOD},
    {"Anchor", Kind::Anchor},
    {"Inline", Kind::Inline},
    {"Material", Kind::Material},
    {"MaterialBinding", Kind::MaterialBinding},
    {"NormalBinding", Kind::NormalBinding},
    {"Coordinate3", Kind::Coordinate3},
    {"Normal", Kind::Normal},
    {"TextureCoordinate2", Kind::TextureCoordinate2},
    {"Texture2", Kind::Texture2},
    {"Texture2Transform", Kind::Texture2Transform},
    {"ShapeHints", Kind::ShapeHints},
    {"Translation", Kind::Translation},
    {"Rotation", Kind::Rotation},
    {"Scale", Kind::Scale},
    {"Transform", Kind::Transform},
    {"MatrixTransform", Kind::MatrixTransform},
    {"Sphere", Kind::Sphere},
    {"Cube", Kind::Cube},
    {"Cylinder", Kind::Cylinder},
    {"Cone", Kind::Cone},
    {"IndexedFaceSet", Kind::IndexedFaceSet},
    {"IndexedLineSet", Kind::IndexedLineSet},
    {"PointSet", Kind::PointSet},
    {"AsciiText", Kind::AsciiText},
    {"FontStyle", Kind::FontStyle},
    {"DirectionalLight", Kind::DirectionalLight},
    {"PointLight", Kind::PointLight},
    {"SpotLight", Kind::SpotLight},
    {"PerspectiveCamera", Kind::PerspectiveCamera},
    {"OrthographicCamera", Kind::OrthographicCamera},
    {"Silent", Kind::Silent},
};

Kind kind_of(Name type) {
    static const std::unordered_map<Name, Kind> by_role = [] {
        std::unordered_map<Name, Kind> t;
        for (const auto& [role, kind] : kRoles) t[intern(role)] = kind;
        return t;
    }();
    const NodeTypeDecl* decl = Registry::builtin().find(Spec::Vrml1, type);
    const auto it = decl ? by_role.find(decl->role) : by_role.end();
    return it == by_role.end() ? Kind::Silent : it->second;  // Info, unknown nodes
}

Binding parse_binding(std::string_view w) {
    if (w == "OVERALL") return Binding::Overall;
    if (w == "PER_PART") return Binding::PerPart;
    if (w == "PER_PART_INDEXED") return Binding::PerPartIndexed;
    if (w == "PER_FACE") return Binding::PerFace;
    if (w == "PER_FACE_INDEXED") return Binding::PerFaceIndexed;
    if (w == "PER_VERTEX") return Binding::PerVertex;
    if (w == "PER_VERTEX_INDEXED") return Binding::PerVertexIndexed;
    return Binding::Default;
}

}  // namespace

std::vector<std::string_view> upgrade_roles() {
    std::vector<std::string_view> out;
    for (const auto& [role, kind] : kRoles) out.push_back(role);
    return out;
}

Upgrader::Upgrader(LoadedScene& scene, const V1File& file, const LoadLimits& limits)
    : scene_(scene),
      tree_(scene.tree),
      registry_(Registry::builtin()),
      file_(file),
      limits_(limits) {
    // Everything inside a USEd group is traversed again: mark it once (each node is marked at most
    // once).
    shared_.assign(file_.nodes.size(), false);
    std::vector<uint32_t> stack;
    for (uint32_t id = 0; id < file_.nodes.size(); ++id) {
        if (!file_.nodes[id].shared || shared_[id]) continue;
        stack.push_back(id);
        while (!stack.empty()) {
            const uint32_t n = stack.back();
            stack.pop_back();
            if (shared_[n]) continue;
            shared_[n] = true;
            const V1Node& node = file_.nodes[n];
            for (uint32_t i = 0; i < node.child_count; ++i)
                stack.push_back(file_.children[node.first_child + i]);
        }
    }
}

bool Upgrader::run(std::vector<NodeId>& roots) {
    try {
        State state;
        OutList out;
        for (uint32_t id : file_.roots) traverse(id, state, out, 0);
        flush(out);
        roots = std::move(out.nodes);
    } catch (const SyntaxError& e) {
        scene_.diagnostics.error({file_.file, e.offset}, e.message);
        return false;
    }
    return true;
}

// ---- output lists ----

void Upgrader::emit(NodeId node, const State& s, OutList& out) {
    if (s.identity) {
        emit_direct(node, out);
        return;
    }
    if (out.has_pending && out.pending_version == s.matrix_version) {
        out.pending.push_back(node);
        return;
    }
    flush(out);
    out.has_pending = true;
    out.pending_version = s.matrix_version;
    out.pending_matrix = s.local;
    out.pending.push_back(node);
}

void Upgrader::emit_direct(NodeId node, OutList& out) {
    flush(out);
    out.nodes.push_back(node);
}

void Upgrader::flush(OutList& out) {
    if (!out.has_pending) return;
    out.nodes.push_back(make_transform(out.pending_matrix, out.pending));
    out.pending.clear();
    out.has_pending = false;
}

NodeId Upgrader::make_transform(const Affine& m, const std::vector<NodeId>& kids) {
    const Names& n = names();
    const TransformFields t = decompose(m);
    Fields f = begin("Transform");
    set(f, n.translation, t.translation);
    set(f, n.rotation, t.rotation);
    set(f, n.scale, t.scale);
    if (t.scale[0] != t.scale[1] || t.scale[1] != t.scale[2])
        set(f, n.scaleOrientation, t.scale_orientation);
    set_nodes(f, n.children, kids);
    return make(f, tree_.nodes[kids.front()].loc);
}

NodeId Upgrader::group_of(std::vector<NodeId> nodes, SourceLoc loc) {
    if (nodes.size() == 1) return nodes.front();
    Fields f = begin("Group");
    set_nodes(f, names().children, nodes);
    return make(f, loc);
}

// ---- traversal ----

// A property node (material, bindings, coordinates, texture, shape hints, font, transform): into
// the state that the shapes after it use.
void Upgrader::set_property(uint32_t id, State& s) {
    const V1Node& node = file_.nodes[id];
    const Names& n = names();
    switch (kind_of(node.type)) {
        case Kind::Material:
            s.material = id;
            break;
        case Kind::MaterialBinding: {
            Binding b = parse_binding(word(id, n.value));
            s.material_binding =
                b == Binding::Default ? Binding::Overall : b;  // DEFAULT is OVERALL for all shapes
            break;
        }
        case Kind::NormalBinding:
            s.normal_binding = parse_binding(word(id, n.value));
            break;
        case Kind::Coordinate3:
            s.coords = id;
            break;
        case Kind::Normal:
            s.normals = id;
            break;
        case Kind::TextureCoordinate2:
            s.texcoords = id;
            break;
        case Kind::Texture2: {
            const bool has_file = !word(id, n.filename).empty();
            FieldView image = get(id, n.image);
            const bool has_image =
                image.numbers.size() >= 3 && image.numbers[0] * image.numbers[1] > 0;
            s.texture = has_file || has_image ? id : kNone;
            break;
        }
        case Kind::Texture2Transform:
            s.texture_transform = id;
            break;  // replaces (VRML 1.0 would compose)
        case Kind::ShapeHints:
            s.shape_hints = id;
            break;
        case Kind::Translation: {
            const Vec3d t = vec3(id, n.translation);
            multiply(s, translation(t[0], t[1], t[2]));
            break;
        }
        case Kind::Rotation:
            multiply(s, rotation(get(id, n.rotation).numbers.data()));
            break;
        case Kind::Scale: {
            const Vec3d f = vec3(id, n.scaleFactor);
            multiply(s, scaling(f[0], f[1], f[2]));
            break;
        }
        case Kind::Transform:
        case Kind::MatrixTransform:
            transform(id, s);
            break;
        case Kind::FontStyle:
            s.font_style = id;
            break;
        default:
            break;
    }
}

void Upgrader::traverse(uint32_t id, State& s, OutList& out, size_t depth) {
    if (++steps_ > limits_.max_nodes)
        fail(id, "the VRML 1.0 scene expands to more than " + std::to_string(limits_.max_nodes) +
                     " nodes (limit; USE of groups inside USE of groups?)");
    if (depth > limits_.max_nesting_depth)
        fail(id, "nodes nested deeper than " + std::to_string(limits_.max_nesting_depth) +
                     " (limit, counting USE of groups)");
    const V1Node& node = file_.nodes[id];
    if (node.vrml97 != kNullNode) {
        emit(node.vrml97, s, out);
        return;
    }
    switch (kind_of(node.type)) {
        case Kind::Separator:
            separator(id, s, out, depth, false);
            break;
        case Kind::Anchor:
            separator(id, s, out, depth, true);
            break;
        case Kind::Group:
            children(id, s, out, depth);
            break;
        case Kind::TransformSeparator: {
            const Affine local = s.local;
            const bool identity = s.identity;
            const uint64_t version = s.matrix_version;
            children(id, s, out, depth);
            s.local = local;
            s.identity = identity;
            s.matrix_version = version;
            break;
        }
        case Kind::Switch:
            switch_node(id, s, out, depth);
            break;
        case Kind::LOD:
            lod(id, s, out, depth);
            break;
        case Kind::Inline:
            inline_node(id, s, out);
            break;
        case Kind::Sphere:
            sphere(id, s, out);
            break;
        case Kind::Cube:
            cube(id, s, out);
            break;
        case Kind::Cylinder:
            cylinder_or_cone(id, s, out, false);
            break;
        case Kind::Cone:
            cylinder_or_cone(id, s, out, true);
            break;
        case Kind::IndexedFaceSet:
            face_set(id, s, out);
            break;
        case Kind::IndexedLineSet:
            line_set(id, s, out);
            break;
        case Kind::PointSet:
            point_set(id, s, out);
            break;
        case Kind::AsciiText:
            ascii_text(id, s, out);
            break;
        case Kind::DirectionalLight:
        case Kind::PointLight:
        case Kind::SpotLight:
            light(id, s, out);
            break;
        case Kind::PerspectiveCamera:
        case Kind::OrthographicCamera:
            camera(id, s, out);
            break;
        case Kind::Silent:
            break;
        default:
            set_property(id, s);
            break;
    }
}

void Upgrader::children(uint32_t id, State& s, OutList& out, size_t depth) {
    const V1Node& node = file_.nodes[id];
    for (uint32_t i = 0; i < node.child_count; ++i)
        traverse(file_.children[node.first_child + i], s, out, depth + 1);
}

// A Separator's content is relative to where it starts, so it depends on the inherited properties
// but not on the inherited matrix: a Separator used again under the same properties is the same
// VRML97 Group.
void Upgrader::separator(uint32_t id, const State& s, OutList& out, size_t depth, bool anchor) {
    const V1Node& node = file_.nodes[id];
    const StateKey k = key(id, s);
    if (shared_[id]) {
        auto it = separators_.find(k);
        if (it != separators_.end()) {
            if (it->second != kNullNode) emit(it->second, s, out);
            return;
        }
    }
    State inner = s;
    inner.local = Affine{};
    inner.identity = true;
    inner.matrix_version = 0;
    inner.in_separator = true;
    OutList list;
    children(id, inner, list, depth);
    flush(list);
    NodeId group = kNullNode;
    if (!list.nodes.empty()) {
        const Names& n = names();
        Fields f = begin(anchor ? "Anchor" : "Group");
        if (anchor) {
            const std::string url = word(id, n.name);
            if (!url.empty()) set_strings(f, n.url, {url});
            const std::string description = word(id, n.description);
            if (!description.empty()) set_strings(f, n.description, {description});
        }
        set_nodes(f, n.children, list.nodes);
        group = make(f, node.loc, node.def_name);
    }
    if (shared_[id]) separators_[k] = group;
    if (group != kNullNode) emit(group, s, out);
}

// Traverses one child of a Switch or LOD into a list of its own, in the current frame.
std::vector<NodeId> Upgrader::traverse_alone(uint32_t child, State& s, size_t depth) {
    OutList list;
    traverse(child, s, list, depth + 1);
    flush(list);
    return std::move(list.nodes);
}

void Upgrader::switch_node(uint32_t id, State& s, OutList& out, size_t depth) {
    const Names& n = names();
    const V1Node& node = file_.nodes[id];
    const int32_t which = int32_of_number(number(id, n.whichChild), -1);
    if (which == -3) {  // all children, like a Group
        children(id, s, out, depth);
        return;
    }
    // Every child is kept (for conversion) in a VRML97 Switch, each read with its own copy of the
    // state; the state afterwards is the chosen child's.
    std::vector<NodeId> choice;
    int32_t chosen = -1;
    State after = s;
    for (uint32_t i = 0; i < node.child_count; ++i) {
        State copy = s;
        std::vector<NodeId> nodes =
            traverse_alone(file_.children[node.first_child + i], copy, depth);
        if (static_cast<int32_t>(i) == which) after = copy;
        if (nodes.empty()) continue;
        if (static_cast<int32_t>(i) == which) chosen = static_cast<int32_t>(choice.size());
        choice.push_back(group_of(std::move(nodes), node.loc));
    }
    if (!choice.empty()) {
        Fields f = begin("Switch");
        set_nodes(f, n.choice, choice);
        set(f, n.whichChoice, {static_cast<double>(chosen)});
        emit_direct(make(f, node.loc, node.def_name), out);
    }
    s = after;
}

void Upgrader::lod(uint32_t id, State& s, OutList& out, size_t depth) {
    const Names& n = names();
    const V1Node& node = file_.nodes[id];
    if (node.child_count == 0) return;
    std::vector<NodeId> levels;
    State after = s;
    for (uint32_t i = 0; i < node.child_count; ++i) {
        State copy = s;
        std::vector<NodeId> nodes =
            traverse_alone(file_.children[node.first_child + i], copy, depth);
        if (i == 0) after = copy;
        levels.push_back(
            group_of(std::move(nodes), node.loc));  // an empty level stays: levels match ranges
    }
    // The levels hold frame coordinates, so the LOD sits in the frame: its centre and ranges are
    // transformed here (ranges by the mean scale of the matrix).
    const Vec3d center = s.local.point(vec3(id, n.center));
    const double det = std::abs(s.local.determinant());
    const double factor = det > 0 ? std::cbrt(det) : 1.0;
    const FieldView given = get(id, n.range);
    std::vector<double> range(given.numbers.begin(), given.numbers.end());
    for (double& r : range) r *= factor;
    Fields f = begin("LOD");
    set_nodes(f, n.level, levels);
    set(f, n.center, center);
    set(f, n.range, range);
    emit_direct(make(f, node.loc, node.def_name), out);
    s = after;
}

void Upgrader::multiply(State& s, const Affine& m) {
    s.local = s.local * m;
    s.identity = s.local.is_identity();
    s.matrix_version = s.identity ? 0 : ++next_version_;
}

void Upgrader::transform(uint32_t id, State& s) {
    const Names& n = names();
    const V1Node& node = file_.nodes[id];
    if (kind_of(node.type) == Kind::Transform) {
        TransformFields t;
        t.translation = vec3(id, n.translation);
        FieldView r = get(id, n.rotation), so = get(id, n.scaleOrientation);
        std::copy(r.numbers.begin(), r.numbers.end(), t.rotation.begin());
        std::copy(so.numbers.begin(), so.numbers.end(), t.scale_orientation.begin());
        t.scale = vec3(id, n.scaleFactor);
        multiply(s, compose(t, vec3(id, n.center)));
        return;
    }
    // MatrixTransform: VRML 1.0 (like Open Inventor) multiplies row vectors, p' = p·M, so the
    // translation is the last row and the column-vector matrix is Mᵀ.
    FieldView v = get(id, n.matrix);
    if (v.numbers.size() < 16) return;
    const double* m = v.numbers.data();
    double w = m[15];
    if (m[3] != 0.0 || m[7] != 0.0 || m[11] != 0.0)
        warn(id,
             "MatrixTransform has a projective part (last column not 0 0 0 1); VRML97 cannot "
             "express it, ignored",
             "vrml1-projective-matrix");
    if (w == 0.0 || !std::isfinite(w)) {
        warn(id, "MatrixTransform with a zero homogeneous scale (m44 = 0) ignored",
             "vrml1-matrix-w");
        return;
    }
    Affine a;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) a.m[r][c] = m[c * 4 + r] / w;
    multiply(s, a);
}

// ---- lights, cameras, inlines ----

void Upgrader::light(uint32_t id, const State& s, OutList& out) {
    const Names& n = names();
    const V1Node& node = file_.nodes[id];
    const Kind kind = kind_of(node.type);
    Fields f = begin(name_text(node.type));
    set(f, n.on, get(id, n.on).numbers);
    set(f, n.intensity, get(id, n.intensity).numbers);
    set(f, n.color, get(id, n.color).numbers);
    auto direction = [&] {
        Vec3d d = s.local.vector(vec3(id, n.direction));
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (len > 0 && std::isfinite(len))
            for (double& x : d) x /= len;
        return d;
    };
    if (kind != Kind::DirectionalLight) {
        set(f, n.location, s.local.point(vec3(id, n.location)));
        // VRML 1.0 lights do not fade with distance: a radius beyond any scene.
        set(f, n.radius, {1e30});
        // Inside a Separator a VRML 1.0 light lights only that Separator's content.
        if (s.in_separator) set(f, n.global, {0.0});
    }
    if (kind != Kind::PointLight) set(f, n.direction, direction());
    if (kind == Kind::SpotLight) {
        // VRML97 limits both angles to (0, pi/2]; dropOffRate 0 (no falloff) is beamWidth =
        // cutOffAngle, and a larger rate narrows the full-intensity cone in proportion.
        const double cut = std::clamp(number(id, n.cutOffAngle), 1e-6, std::numbers::pi / 2);
        const double drop = std::clamp(number(id, n.dropOffRate), 0.0, 1.0);
        set(f, n.cutOffAngle, {cut});
        set(f, n.beamWidth, {std::max(cut * (1.0 - drop), 1e-6)});
    }
    emit_direct(make(f, node.loc, node.def_name), out);
}

void Upgrader::camera(uint32_t id, const State& s, OutList& out) {
    const Names& n = names();
    const V1Node& node = file_.nodes[id];
    const bool ortho = kind_of(node.type) == Kind::OrthographicCamera;
    Fields f = begin(ortho ? "OrthoViewpoint" : "Viewpoint");
    set(f, n.position, get(id, n.position).numbers);
    set(f, n.orientation, get(id, n.orientation).numbers);
    if (ortho) {
        const double h = number(id, n.height) / 2;
        set(f, n.fieldOfView, {-h, -h, h, h});
    } else {
        set(f, n.fieldOfView, get(id, n.heightAngle).numbers);
    }
    emit(make(f, node.loc, node.def_name), s, out);
}

void Upgrader::inline_node(uint32_t id, const State& s, OutList& out) {
    const Names& n = names();
    const V1Node& node = file_.nodes[id];
    const std::string url = word(id, n.name);
    if (url.empty()) {
        warn(id, "WWWInline without a name (URL) skipped", "vrml1-inline-empty");
        return;
    }
    Fields f = begin("Inline");
    set_strings(f, n.url, {url});
    const Vec3d size = vec3(id, n.bboxSize);
    if (size[0] > 0 || size[1] > 0 || size[2] > 0) {  // VRML 1.0 writes 0 0 0 for "no box"
        set(f, n.bboxSize, size);
        set(f, n.bboxCenter, vec3(id, n.bboxCenter));
    }
    emit(make(f, node.loc, node.def_name), s, out);
}

bool upgrade(LoadedScene& scene, const V1File& file, const LoadLimits& limits,
             std::vector<NodeId>& roots) {
    Upgrader upgrader(scene, file, limits);
    return upgrader.run(roots);
}

}  // namespace vr::vrml1
