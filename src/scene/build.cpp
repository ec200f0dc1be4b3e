// Node tree -> typed scene: grouping nodes, Shape/Appearance/Material/textures, lights and bindable
// nodes. Geometry nodes are in build_geometry.cpp.
#include "scene/build.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "core/format.h"
#include "core/huge_pages.h"
#include "parser/field_value.h"
#include "parser/registry.h"
#include "scene/build_internal.h"
#include "scene/hints.h"
#include "scene/report.h"
#include "scene/transform.h"
#include "scene/translated_shape.h"

namespace vr {
namespace detail {

namespace {

enum class ChildKind : uint8_t {
    Group,
    Transform,
    MatrixTransform,
    Billboard,
    Switch,
    LOD,
    Inline,
    GeoLocation,  // GeoLocation and GeoTransform
    GeoLOD,
    CADFace,
    LayoutGroup,
    Layer,
    Shape,
    Light,
    Viewpoint,
    Background,
    Fog,
    NavigationInfo,
    LayerSet,
    ClipPlane,
    LocalFog,
    Silent,
    NotModelled,
};

// The grammar's roles ("Name : Role {" in grammar/*.nodes) of child nodes, as the builder's kinds.
constexpr std::pair<const char*, ChildKind> kChildRoles[] = {
    {"Group", ChildKind::Group},
    {"Transform", ChildKind::Transform},
    {"MatrixTransform", ChildKind::MatrixTransform},
    {"Billboard", ChildKind::Billboard},
    {"Switch", ChildKind::Switch},
    {"LOD", ChildKind::LOD},
    {"Inline", ChildKind::Inline},
    {"CADFace", ChildKind::CADFace},
    {"GeoLocation", ChildKind::GeoLocation},
    {"GeoTransform", ChildKind::GeoLocation},
    {"GeoLOD", ChildKind::GeoLOD},
    {"Shape", ChildKind::Shape},
    {"Light", ChildKind::Light},
    {"Viewpoint", ChildKind::Viewpoint},
    {"Background", ChildKind::Background},
    {"Fog", ChildKind::Fog},
    {"NavigationInfo", ChildKind::NavigationInfo},
    {"LayoutGroup", ChildKind::LayoutGroup},
    {"Layer", ChildKind::Layer},
    {"LayerSet", ChildKind::LayerSet},
    {"ClipPlane", ChildKind::ClipPlane},
    {"LocalFog", ChildKind::LocalFog},
    {"Silent", ChildKind::Silent},  // draws nothing at time 0 (docs/input.md)
};

ChildKind child_kind(const NodeTypeDecl* decl) {
    static const std::unordered_map<Name, ChildKind> by_role = [] {
        std::unordered_map<Name, ChildKind> t;
        for (const auto& [role, kind] : kChildRoles) t[intern(role)] = kind;
        return t;
    }();
    if (!decl) return ChildKind::NotModelled;
    const auto it = by_role.find(decl->role);
    return it == by_role.end() ? ChildKind::NotModelled : it->second;
}

}  // namespace

std::vector<std::string_view> child_roles() {
    std::vector<std::string_view> out;
    for (const auto& [role, kind] : kChildRoles) out.push_back(role);
    return out;
}

// ------------------------------------------------------------------------------------------------
// Field readers

FieldView Builder::read(NodeId n, Name f, Many many, std::initializer_list<ValueKind> kinds) const {
    // One named result, returned on every path: GCC then builds it in the caller's slot. With a
    // second `return {}` it copied the 80-byte view with one 64-byte load right after get()
    // stored it field by field, a store-forwarding stall on every field read (bench/README.md,
    // "Figures behind the comments").
    FieldView v = tree_.get(n, f);
    const bool kind_ok = std::find(kinds.begin(), kinds.end(), v.type.kind) != kinds.end();
    const bool many_ok = many == Many::Either || v.type.multi == (many == Many::MF);
    if (!(v.found && kind_ok && many_ok)) {
        std::string why = std::string(tree_.type_name(n)) + "." + std::string(name_text(f));
        why += v.found ? " is " + std::string(type_name(v.type)) + ", read as another type"
                       : " is not in the node's interface";
        misreads_.push_back(std::move(why));
        v = FieldView();
    }
    return v;
}

bool Builder::in_range(NodeId n, Name f, std::initializer_list<double> value) const {
    const NodeTypeDecl* decl = tree_.decl(n);
    const FieldDecl* field =
        decl ? Registry::builtin().lookup_field(decl->spec, *decl, f) : nullptr;
    if (!field) {
        misreads_.push_back(std::string(tree_.type_name(n)) + "." + std::string(name_text(f)) +
                            " has no range: not in the node's interface");
        return true;
    }
    return field->numeric_range.contains({value.begin(), value.size()});
}

FieldView Builder::default_of(Name node_type, Name f) const {
    const Registry& registry = Registry::builtin();
    const NodeTypeDecl* decl = registry.find(Spec::X3d, node_type);
    const FieldDecl* field = decl ? decl->find(f) : nullptr;
    if (!field || field->default_field == UINT32_MAX)
        throw std::logic_error("the grammar has no default for " +
                               std::string(name_text(node_type)) + "." + std::string(name_text(f)));
    return field->default_tree->view(field->default_tree->fields[field->default_field]);
}

double Builder::number(NodeId n, Name f) const {
    const FieldView v =
        read(n, f, Many::SF, {ValueKind::Float, ValueKind::Double, ValueKind::Time});
    return v.numbers.empty() ? 0.0 : v.numbers[0];
}
int32_t Builder::integer(NodeId n, Name f) const {
    const FieldView v = read(n, f, Many::SF, {ValueKind::Int32});
    // Every field read here takes a negative value as "none" or as an error.
    return v.numbers.empty() ? 0 : int32_of_number(v.numbers[0], -1);
}
bool Builder::boolean(NodeId n, Name f) const {
    const FieldView v = read(n, f, Many::SF, {ValueKind::Bool});
    return !v.numbers.empty() && v.numbers[0] != 0.0;
}
Vec2 Builder::vec2(NodeId n, Name f) const {
    const FieldView v = read(n, f, Many::SF, {ValueKind::Vec2f, ValueKind::Vec2d});
    return v.numbers.size() < 2 ? Vec2(0.0) : Vec2(v.numbers[0], v.numbers[1]);
}
Vec3 Builder::vec3(NodeId n, Name f) const {
    const FieldView v =
        read(n, f, Many::SF, {ValueKind::Vec3f, ValueKind::Vec3d, ValueKind::Color});
    return v.numbers.size() < 3 ? Vec3(0.0) : Vec3(v.numbers[0], v.numbers[1], v.numbers[2]);
}
Vec4 Builder::rotation(NodeId n, Name f) const {
    const FieldView v = read(n, f, Many::SF, {ValueKind::Rotation});
    if (v.numbers.size() < 4) return Vec4(0.0);
    return Vec4(v.numbers[0], v.numbers[1], v.numbers[2], v.numbers[3]);
}
std::vector<double> Builder::numbers(NodeId n, Name f) const {
    const FieldView v = read(n, f, Many::MF, {ValueKind::Float, ValueKind::Double});
    return {v.numbers.begin(), v.numbers.end()};
}
std::vector<int32_t> Builder::integers(NodeId n, Name f) const {
    const FieldView v = read(n, f, Many::MF, {ValueKind::Int32});
    std::vector<int32_t> out(v.numbers.size());
    for (size_t i = 0; i < out.size(); ++i) {
        // Values without an int32 cannot be valid indices; -2 is rejected by every index check.
        out[i] = int32_of_number(v.numbers[i], -2);
    }
    return out;
}
std::vector<Vec2> Builder::vec2s(NodeId n, Name f) const {
    const FieldView v = read(n, f, Many::MF, {ValueKind::Vec2f, ValueKind::Vec2d});
    std::vector<Vec2> out(v.numbers.size() / 2);
    for (size_t i = 0; i < out.size(); ++i) out[i] = Vec2(v.numbers[2 * i], v.numbers[2 * i + 1]);
    return out;
}
std::vector<Vec3> Builder::vec3s(NodeId n, Name f) const {
    const FieldView v =
        read(n, f, Many::MF,
             {ValueKind::Vec3f, ValueKind::Vec3d, ValueKind::Color, ValueKind::ColorRGBA});
    const size_t stride = v.type.kind == ValueKind::ColorRGBA ? 4 : 3;
    std::vector<Vec3> out(v.numbers.size() / stride);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = Vec3(v.numbers[stride * i], v.numbers[stride * i + 1], v.numbers[stride * i + 2]);
    return out;
}
std::vector<std::string> Builder::strings(NodeId n, Name f) const {
    const FieldView v = read(n, f, Many::Either, {ValueKind::String});
    return {v.strings.begin(), v.strings.end()};
}
NodeId Builder::node(NodeId n, Name f) const {
    const FieldView v = read(n, f, Many::SF, {ValueKind::Node});
    return v.nodes.empty() ? kNullNode : v.nodes[0];
}
std::span<const NodeId> Builder::nodes(NodeId n, Name f) const {
    return read(n, f, Many::MF, {ValueKind::Node}).nodes;
}

sg::Origin Builder::origin(NodeId n) const {
    const Node& node = tree_.nodes[n];
    return sg::Origin{tree_.type(n), node.def_name, node.loc};
}

sg::Index Builder::hints(NodeId n) {
    const NodeId metadata = node(n, "metadata"_n);
    if (metadata == kNullNode) return sg::kNone;
    const sg::Hints h = read_hints(tree_, metadata, diagnostics_);
    if (!h.any()) return sg::kNone;
    scene_.hints.push_back(h);
    return static_cast<sg::Index>(scene_.hints.size() - 1);
}

void Builder::warn(NodeId n, std::string_view cause, const std::string& message) {
    const sg::Origin o = origin(n);
    std::string key(o.type_text());
    key += ':';
    key += cause;
    diagnostics_.warning(o.loc, node_label(o) + ": " + message, key);
}

std::filesystem::path Builder::file_of(NodeId n) const {
    const SourceLoc loc = tree_.nodes[n].loc;
    if (loc.valid() && loc.file < loaded_.sources.size())
        return loaded_.sources.file(loc.file).path;
    return loaded_.main_file;
}

// ------------------------------------------------------------------------------------------------
// Graph

Builder::Builder(const LoadedScene& loaded, Diagnostics& diagnostics)
    : Builder(loaded, loaded.tree, diagnostics) {}

Builder::Builder(const LoadedScene& loaded, const NodeTree& tree, Diagnostics& diagnostics)
    : loaded_(loaded), tree_(tree), diagnostics_(diagnostics) {
    count_references();
}

void Builder::count_references() {
    const size_t words = (tree_.nodes.size() + 63) / 64;
    referred_once_.assign(words, 0);
    referred_twice_.assign(words, 0);
    size_t shared = 0;
    auto refer = [&](NodeId id) {
        if (id >= tree_.nodes.size()) return;  // kNullNode
        const uint64_t bit = uint64_t(1) << (id % 64);
        uint64_t& once = referred_once_[id / 64];
        uint64_t& twice = referred_twice_[id / 64];
        if ((once & bit) && !(twice & bit)) {
            twice |= bit;
            ++shared;
        }
        once |= bit;
    };
    for (NodeId id : tree_.node_refs) refer(id);
    for (NodeId id : tree_.roots) refer(id);
    for (const auto& [inline_node, roots] : tree_.inline_roots)
        for (NodeId id : roots) refer(id);
    // A consumed piece's USEs of the tree's nodes (fragments.h) refer to them too.
    if (&tree_ == &loaded_.tree)
        for (const ConsumedPiece& p : loaded_.consumed_pieces)
            for (NodeId id : p.outer_nodes) refer(id);
    memo_.reserve(shared);
    shared_nodes_ = shared;
}

size_t MaterialKeyHash::operator()(const MaterialKey& key) const {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (uint64_t k : key) {
        h ^= k + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
    }
    return size_t(h ^ (h >> 31));
}

Scene Builder::build() { return build(tree_.roots); }

Scene Builder::build(std::span<const NodeId> roots) {
    reserve();
    scene_.main_file = loaded_.main_file;
    scene_.allowed_roots = loaded_.allowed_roots;
    scene_.groups.emplace_back();  // the root
    scene_.groups[Scene::kRoot].origin.type = intern("(root)");
    if (tree_.root_length_scale != 1.0)
        scale_lengths(scene_.groups[Scene::kRoot], tree_.root_length_scale);
    add_root_children(roots);
    return std::move(scene_);
}

void Builder::reserve() {
    // Arenas sized from the node counts up front: PyMOL files hold 1e5 shapes, and growing the
    // arenas by doubling would move (and touch) every element several times. Appearances,
    // materials and geometries are mostly merged (see same_material_): they grow as needed.
    size_t groups = 1, shapes = 0, transforms = 0;
    std::vector<ChildKind> kinds;  // by NodeTree::kinds: a few, for millions of nodes
    for (const NodeKind& k : tree_.kinds) kinds.push_back(child_kind(k.decl));
    for (const Node& node : tree_.nodes) {
        const ChildKind kind = kinds[node.kind];
        if (kind == ChildKind::Shape) ++shapes;
        if (kind <= ChildKind::Layer) ++groups;
        if (kind == ChildKind::Transform) ++transforms;
    }
    // Every child is a reference in the tree: an upper bound (pages past the end stay untouched).
    size_t refs = tree_.node_refs.size() + tree_.roots.size();
    for (const auto& [inline_node, roots] : tree_.inline_roots) refs += roots.size();
    // (Fragments come as chunks of their own, but the root's block has a slot for each of their
    // top-level nodes: without room for those, the first child block after it would move the
    // root's block, holding it twice for a moment, 16 bytes a spliced atom.)
    for (const ConsumedPiece& p : loaded_.consumed_pieces) refs += p.roots;
    scene_.groups.reserve(groups);
    scene_.shapes.reserve(shapes);
    scene_.translations.reserve(transforms);
    scene_.child_refs.reserve(refs);
}

void Builder::add_children(sg::Index group, std::span<const NodeId> children) {
    // The group's block is claimed before its children are built (child groups append theirs
    // after it) and filled from the front; children that draw nothing leave unused slots at its
    // end, which cost less than building the list elsewhere and copying it.
    const size_t first = scene_.child_refs.size();
    scene_.child_refs.resize(first + children.size());
    size_t count = 0;
    for (size_t i = 0; i < children.size(); ++i) {
        const NodeId id = children[i];
        if (id != kNullNode && id < tree_.nodes.size())
            if (const auto ref = child(id)) scene_.child_refs[first + count++] = *ref;
        if (group == Scene::kRoot && release_) release_->built(i);
    }
    sg::Group& g = scene_.groups[group];
    g.first_child = static_cast<uint32_t>(first);
    g.child_count = static_cast<uint32_t>(count);
}

void Builder::add_root_children(std::span<const NodeId> roots) {
    const std::vector<ConsumedPiece>& pieces = loaded_.consumed_pieces;
    if (!fragments_ || pieces.empty()) return add_children(Scene::kRoot, roots);
    // One block, as long as the sequential build's: a slot per top-level node read.
    const size_t first = scene_.child_refs.size();
    size_t slots = roots.size();
    for (const ConsumedPiece& p : pieces) slots += p.roots;
    scene_.child_refs.resize(first + slots);
    size_t count = 0;
    auto piece = pieces.begin();
    for (size_t i = 0; i <= roots.size(); ++i) {
        for (; piece != pieces.end() && piece->before_root == i; ++piece) {
            Scene* f = fragments_->fragment(piece->piece);
            if (!f) throw std::logic_error("a consumed piece has no scene fragment");
            splice(*f, *piece, first, count);
            if (free_fragments_) fragments_->release(piece->piece);
        }
        if (i == roots.size()) break;
        if (roots[i] != kNullNode && roots[i] < tree_.nodes.size())
            if (const auto ref = child(roots[i])) scene_.child_refs[first + count++] = *ref;
        if (release_) release_->built(i);
    }
    scene_.groups[Scene::kRoot].first_child = static_cast<uint32_t>(first);
    scene_.groups[Scene::kRoot].child_count = static_cast<uint32_t>(count);
}

std::optional<sg::ChildRef> Builder::child(NodeId id) {
    if (Memo* memo = shared(id)) {
        if (memo->state == 2) {
            if (memo->child.index == sg::kNone) return std::nullopt;
            return memo->child;
        }
        if (memo->state == 1) {
            warn(id, "cycle", "is used inside itself (DEF/USE cycle); the inner use is skipped");
            return std::nullopt;
        }
    }
    if (depth_ >= kMaxDepth) {
        warn(id, "depth",
             "is nested more than " + std::to_string(kMaxDepth) + " levels deep; skipped");
        return std::nullopt;
    }
    if (Memo* memo = shared(id)) memo->state = 1;
    ++depth_;
    const std::optional<sg::ChildRef> ref = make_child(id);
    --depth_;
    if (Memo* memo = shared(id)) {  // the map may have grown: look again
        memo->state = 2;
        memo->child = ref ? *ref : sg::ChildRef{sg::NodeKind::Group, sg::kNone};
    }
    return ref;
}

std::optional<sg::ChildRef> Builder::make_child(NodeId id) {
    using sg::NodeKind;
    switch (child_kind(tree_.decl(id))) {
        case ChildKind::Transform:
            return translated_or_group(id, make_group(id));
        case ChildKind::Group:
        case ChildKind::MatrixTransform:
        case ChildKind::Billboard:
        case ChildKind::Switch:
        case ChildKind::LOD:
        case ChildKind::Inline:
        case ChildKind::GeoLocation:
        case ChildKind::GeoLOD:
        case ChildKind::CADFace:
        case ChildKind::LayoutGroup:
            return sg::ChildRef{NodeKind::Group, make_group(id)};
        case ChildKind::Layer:
            warn(id, "layer-child",
                 "is a layer outside a LayerSet's `layers`; drawn as a group of the scene");
            return sg::ChildRef{NodeKind::Group, make_group(id)};
        case ChildKind::LayerSet:
            make_layer_set(id);
            return std::nullopt;
        case ChildKind::ClipPlane:
            return make_clip_plane(id);
        case ChildKind::LocalFog:
            return make_local_fog(id);
        case ChildKind::Shape:
            return make_shape(id);
        case ChildKind::Light:
            return sg::ChildRef{NodeKind::Light, make_light(id)};
        case ChildKind::Viewpoint:
            return sg::ChildRef{NodeKind::Viewpoint, make_viewpoint(id)};
        case ChildKind::Background:
            return sg::ChildRef{NodeKind::Background, make_background(id)};
        case ChildKind::Fog:
            return sg::ChildRef{NodeKind::Fog, make_fog(id)};
        case ChildKind::NavigationInfo:
            return sg::ChildRef{NodeKind::NavigationInfo, make_navigation_info(id)};
        case ChildKind::Silent:
            return std::nullopt;
        case ChildKind::NotModelled:
            diagnostics_.warning(
                tree_.nodes[id].loc,
                std::string(tree_.type_name(id)) + " is not rendered by vrmlray; skipped",
                "not-modelled:" + std::string(tree_.type_name(id)));
            return std::nullopt;
    }
    return std::nullopt;
}

sg::Index Builder::make_group(NodeId id) {
    const sg::Index index = static_cast<sg::Index>(scene_.groups.size());
    scene_.groups.emplace_back();
    sg::Group group;
    group.origin = origin(id);
    std::span<const NodeId> children;
    std::vector<NodeId> chosen;  // Switch/LOD: the one active child
    switch (child_kind(tree_.decl(id))) {
        case ChildKind::Transform: {
            TransformFields f;
            f.translation = vec3(id, "translation"_n);
            f.rotation = rotation(id, "rotation"_n);
            f.scale = vec3(id, "scale"_n);
            f.scale_orientation = rotation(id, "scaleOrientation"_n);
            f.center = vec3(id, "center"_n);
            set_group_matrix(group, id, transform_matrix(f));
            children = nodes(id, "children"_n);
            break;
        }
        case ChildKind::MatrixTransform:
            set_group_matrix(group, id, matrix_transform(id));
            children = nodes(id, "children"_n);
            break;
        case ChildKind::Billboard:
            group.transform_kind = sg::GroupTransform::Billboard;
            group.transform = static_cast<sg::Index>(scene_.billboard_axes.size());
            scene_.billboard_axes.push_back(vec3(id, "axisOfRotation"_n));
            children = nodes(id, "children"_n);
            break;
        case ChildKind::Switch: {
            // VRML97 `choice`, X3D `children`: the reader accepts both spellings, so take the one
            // that is set.
            const std::span<const NodeId> choice = nodes(id, "choice"_n);
            const std::span<const NodeId> all = !choice.empty() ? choice : nodes(id, "children"_n);
            const int32_t which = integer(id, "whichChoice"_n);
            if (which >= 0 && static_cast<size_t>(which) < all.size()) chosen.push_back(all[which]);
            children = chosen;
            break;
        }
        case ChildKind::LOD: {
            const std::span<const NodeId> level =
                nodes(id, "level"_n);  // VRML97 `level`, X3D `children`
            const std::span<const NodeId> all = !level.empty() ? level : nodes(id, "children"_n);
            if (!all.empty()) chosen.push_back(all[0]);
            children = chosen;
            break;
        }
        case ChildKind::Inline: {
            group.inline_content = true;
            const auto it = tree_.inline_roots.find(id);
            if (it != tree_.inline_roots.end() && boolean(id, "load"_n)) children = it->second;
            if (const auto scale = tree_.inline_length_scale.find(id);
                scale != tree_.inline_length_scale.end())
                scale_lengths(group, scale->second);
            break;
        }
        case ChildKind::GeoLocation:
            set_group_matrix(id, group, geo_group_matrix(id));
            children = nodes(id, "children"_n);
            break;
        case ChildKind::GeoLOD:
            children = geo_lod_children(id, group.inline_content);
            break;
        case ChildKind::CADFace:
            chosen.push_back(node(id, "shape"_n));
            children = chosen;
            break;
        case ChildKind::LayoutGroup:
        case ChildKind::Layer:
            read_group_layout(id, group);
            children = nodes(id, "children"_n);
            break;
        default:
            children = nodes(id, "children"_n);
            break;
    }
    scene_.groups[index] = group;
    add_children(index, children);
    return index;
}

sg::ChildRef Builder::translated_or_group(NodeId id, sg::Index g) {
    const sg::ChildRef as_group{sg::NodeKind::Group, g};
    // A node referred to twice is shared whether it has a DEF or not (the VRML 1.0 reader hangs
    // one Shape under every atom of a state): its memo keeps its typed index.
    if (shared(id)) return as_group;
    for (const NodeId child : nodes(id, "children"_n))
        if (child != kNullNode && child < tree_.nodes.size() && shared(child)) return as_group;
    const sg::Group group = scene_.groups[g];
    if (g + 1 != scene_.groups.size() || group.child_count != 1 ||
        group.transform_kind != sg::GroupTransform::Translation ||
        group.transform + 1 != scene_.translations.size())
        return as_group;
    const sg::ChildRef only = scene_.child_refs[group.first_child];
    if (only.kind != sg::NodeKind::Shape || only.index + 1 != scene_.shapes.size()) return as_group;
    const std::optional<sg::TranslatedShape> t =
        translated_shape(group, scene_.translations[group.transform], scene_.shapes[only.index]);
    if (!t) return as_group;
    // The group's child block is the last one: a Shape child claims none, and a child that
    // claimed one (a group) would have been counted.
    scene_.groups.resize(g);
    scene_.translations.resize(group.transform);
    scene_.shapes.resize(only.index);
    scene_.child_refs.resize(group.first_child);
    const auto index = static_cast<sg::Index>(scene_.translated_shapes.size());
    scene_.translated_shapes.push_back(*t);
    return sg::ChildRef{sg::NodeKind::TranslatedShape, index};
}

// A file's UNIT length factor (parser/units.h) as the scale of the group holding its top-level
// nodes: every length of the file lives in that group's coordinate system.
void Builder::scale_lengths(sg::Group& group, double scale) {
    group.transform_kind = sg::GroupTransform::Matrix;
    group.transform = static_cast<sg::Index>(scene_.matrices.size());
    scene_.matrices.push_back(Mat4(Mat3(scale)));
}

std::optional<sg::ChildRef> Builder::make_shape(NodeId id) {
    if (!boolean(id, "visible"_n)) return std::nullopt;  // X3D 4 Shape.visible
    sg::Shape shape;
    shape.origin = origin(id);
    shape.hints = hints(id);
    const NodeId app = node(id, "appearance"_n);
    if (app != kNullNode) shape.appearance = appearance(app);
    const NodeId geo = node(id, "geometry"_n);
    if (geo != kNullNode) shape.geometry = geometry(geo);
    if (shape.geometry == sg::kNone) return std::nullopt;
    const sg::Index index = static_cast<sg::Index>(scene_.shapes.size());
    scene_.shapes.push_back(std::move(shape));
    return sg::ChildRef{sg::NodeKind::Shape, index};
}

// ------------------------------------------------------------------------------------------------
// Appearance

sg::Index Builder::appearance(NodeId id) {
    // A piece's USE of an Appearance DEF'd before it (fragments.h): the splice resolves it.
    if (is_outer_node(id)) return id;
    Memo* memo = shared(id);
    if (memo && memo->typed != sg::kNone) return memo->typed;
    if (type(id) != "Appearance"_n) {
        warn(id, "wrong-type",
             "cannot be an appearance; the shape is drawn with the default appearance");
        return sg::kNone;
    }
    sg::Appearance a;
    a.origin = origin(id);
    if (const NodeId m = node(id, "material"_n); m != kNullNode) a.material = material(m);
    if (const NodeId t = node(id, "texture"_n); t != kNullNode) a.texture = texture(t);
    if (a.texture == sg::kNone && a.material != sg::kNone) {
        // X3D 4: a texture may sit in the material instead (Material.diffuseTexture,
        // PhysicalMaterial.baseTexture, UnlitMaterial.emissiveTexture); it stands in for the
        // Appearance's texture (the materials' other texture fields are not modelled).
        const NodeId m = node(id, "material"_n);
        const Name field = type(m) == "PhysicalMaterial"_n ? "baseTexture"_n
                           : type(m) == "UnlitMaterial"_n  ? "emissiveTexture"_n
                                                           : "diffuseTexture"_n;
        if (const NodeId t = node(m, field); t != kNullNode) a.texture = texture(t);
    }
    if (const NodeId tt = node(id, "textureTransform"_n); tt != kNullNode)
        read_texture_transform(tt, a);
    const uint32_t file = a.origin.loc.get().file;
    a.texture_modulates =
        a.texture != sg::kNone && file < loaded_.x3d_major.size() && loaded_.x3d_major[file] >= 4;
    sg::Index index = static_cast<sg::Index>(scene_.appearances.size());
    if (uint64_t key; appearance_key(a, key)) index = same_appearance_.find_or_add(key, index);
    if (index == scene_.appearances.size()) scene_.appearances.push_back(std::move(a));
    if ((memo = shared(id))) memo->typed = index;
    return index;
}

bool material_key(const sg::Material& m, MaterialKey& key) {
    const double values[] = {m.diffuse_color.x,   m.diffuse_color.y,  m.diffuse_color.z,
                             m.specular_color.x,  m.specular_color.y, m.specular_color.z,
                             m.emissive_color.x,  m.emissive_color.y, m.emissive_color.z,
                             m.ambient_intensity, m.shininess,        m.transparency,
                             m.metallic,          m.roughness};
    bool mergeable = m.hints == sg::kNone;  // hints belong to their node
    key[0] = uint64_t(m.model);
    for (size_t i = 0; i < std::size(values); ++i) {
        mergeable = mergeable && std::isfinite(values[i]);  // warned per node by flattening
        key[i + 1] = std::bit_cast<uint64_t>(values[i]);
    }
    return mergeable;
}

sg::Index Builder::material(NodeId id) {
    if (Memo* memo = shared(id); memo && memo->typed != sg::kNone) return memo->typed;
    sg::Material m;
    m.origin = origin(id);
    const Name t = type(id);
    const bool phong = t == "Material"_n || t == "TwoSidedMaterial"_n;
    if (!phong && t != "PhysicalMaterial"_n && t != "UnlitMaterial"_n) {
        warn(id, "wrong-type", "cannot be a material; the shape is unlit");
        return sg::kNone;
    }
    // TwoSidedMaterial: its front-face fields (the back ones are not modelled). The Phong fields
    // PhysicalMaterial and UnlitMaterial lack shade as a Material's defaults would.
    const auto phong_number = [&](Name f) {
        return phong ? number(id, f) : default_of("Material"_n, f).numbers[0];
    };
    const auto phong_colour = [&](Name f) {
        if (phong) return vec3(id, f);
        const auto c = default_of("Material"_n, f).numbers;
        return Vec3(c[0], c[1], c[2]);
    };
    m.ambient_intensity = phong_number("ambientIntensity"_n);
    m.diffuse_color = phong_colour("diffuseColor"_n);
    m.specular_color = phong_colour("specularColor"_n);
    m.shininess = phong_number("shininess"_n);
    if (t == "PhysicalMaterial"_n) {
        m.model = sg::MaterialModel::Physical;
        m.diffuse_color = vec3(id, "baseColor"_n);
        m.metallic = number(id, "metallic"_n);
        m.roughness = number(id, "roughness"_n);
    } else if (t == "UnlitMaterial"_n) {
        m.model = sg::MaterialModel::Unlit;
    }
    m.emissive_color = vec3(id, "emissiveColor"_n);
    m.transparency = number(id, "transparency"_n);
    m.hints = hints(id);
    sg::Index index = static_cast<sg::Index>(scene_.materials.size());
    MaterialKey key;
    if (material_key(m, key)) index = same_material_.try_emplace(key, index).first->second;
    if (index == scene_.materials.size()) scene_.materials.push_back(std::move(m));
    if (Memo* memo = shared(id)) memo->typed = index;
    return index;
}

sg::Index Builder::texture(NodeId id) {
    if (Memo* memo = shared(id); memo && memo->typed != sg::kNone) return memo->typed;
    const Name t = type(id);
    if (t == "MultiTexture"_n) {
        // The first texture stands for the stack (multi-texturing is not modelled).
        for (NodeId inner : nodes(id, "texture"_n))
            if (inner != kNullNode && type(inner) != "MultiTexture"_n) {
                const sg::Index index = texture(inner);
                if (Memo* memo = shared(id)) memo->typed = index;
                return index;
            }
        return sg::kNone;
    }
    sg::Texture tex;
    tex.origin = origin(id);
    if (t == "ImageTexture"_n || t == "PixelTexture"_n) {
        // 18.4.9: a TextureProperties node overrides repeatS and repeatT.
        // (VRML97's textures have no such field.)
        const bool has_props = tree_.decl(id) && tree_.decl(id)->find("textureProperties"_n);
        if (const NodeId props = has_props ? node(id, "textureProperties"_n) : kNullNode;
            props != kNullNode) {
            read_texture_properties(props, tex.sampling);
        } else {
            tex.sampling.wrap_s =
                boolean(id, "repeatS"_n) ? TextureWrap::Repeat : TextureWrap::ClampToEdge;
            tex.sampling.wrap_t =
                boolean(id, "repeatT"_n) ? TextureWrap::Repeat : TextureWrap::ClampToEdge;
        }
    }
    if (t == "ImageTexture"_n) {
        tex.kind = sg::TextureKind::Image;
        tex.urls = strings(id, "url"_n);
        tex.from_file = file_of(id);
        if (tex.urls.empty()) return sg::kNone;
    } else if (t == "PixelTexture"_n) {
        tex.kind = sg::TextureKind::Pixel;
        const FieldView image = tree_.get(id, "image"_n);
        const auto& v = image.numbers;
        if (v.size() < 3) return sg::kNone;
        const double w = v[0], h = v[1], c = v[2];
        const bool ok = w >= 0 && h >= 0 && c >= 1 && c <= 4 && w * h + 3 <= double(v.size());
        if (!ok) {
            warn(id, "image",
                 "has an SFImage whose size does not match its pixels; the shape is untextured");
            return sg::kNone;
        }
        if (w == 0 || h == 0) return sg::kNone;  // the default: no image
        tex.width = int(w);
        tex.height = int(h);
        tex.components = int(c);
        tex.pixels.resize(size_t(w) * size_t(h));
        for (size_t i = 0; i < tex.pixels.size(); ++i)
            tex.pixels[i] = static_cast<uint32_t>(int64_t(v[3 + i]));
    } else {
        warn(id, "not-modelled", "is not a texture type vrmlray renders; the shape is untextured");
        return sg::kNone;
    }
    const sg::Index index = static_cast<sg::Index>(scene_.textures.size());
    scene_.textures.push_back(std::move(tex));
    if (Memo* memo = shared(id)) memo->typed = index;
    return index;
}

void Builder::read_texture_transform(NodeId id, sg::Appearance& a) {
    if (type(id) == "MultiTextureTransform"_n) {
        const auto inner = nodes(id, "textureTransform"_n);
        if (!inner.empty() && inner[0] != kNullNode && type(inner[0]) == "TextureTransform"_n)
            read_texture_transform(inner[0], a);
        return;
    }
    if (type(id) != "TextureTransform"_n) {
        warn(id, "wrong-type", "cannot be a texture transform; ignored");
        return;
    }
    a.has_texture_transform = true;
    sg::TextureTransform& tt = a.texture_transform;
    tt.center = vec2(id, "center"_n);
    tt.rotation = number(id, "rotation"_n);
    tt.scale = vec2(id, "scale"_n);
    tt.translation = vec2(id, "translation"_n);
}

// ------------------------------------------------------------------------------------------------
// Lights and bindable nodes

sg::Index Builder::make_light(NodeId id) {
    sg::Light l;
    l.origin = origin(id);
    const std::string_view t = tree_.type_name(id);
    l.type = t == "DirectionalLight" ? sg::LightType::Directional
             : t == "PointLight"     ? sg::LightType::Point
                                     : sg::LightType::Spot;
    l.on = boolean(id, "on"_n);
    // VRML97 has no `global` field; the X3D defaults (FALSE for directional, TRUE for point and
    // spot lights) are exactly VRML97's scoping rules, and the reader gives them for .wrl files
    // too.
    l.global = boolean(id, "global"_n);
    l.color = vec3(id, "color"_n);
    l.intensity = number(id, "intensity"_n);
    l.ambient_intensity = number(id, "ambientIntensity"_n);
    // Each light type has only some of these fields; the others stay zero and unused.
    if (l.type != sg::LightType::Point) l.direction = vec3(id, "direction"_n);
    if (l.type != sg::LightType::Directional) {
        l.location = vec3(id, "location"_n);
        l.attenuation = vec3(id, "attenuation"_n);
        l.radius = number(id, "radius"_n);
    }
    if (l.type == sg::LightType::Spot) {
        l.beam_width = number(id, "beamWidth"_n);
        l.cut_off_angle = number(id, "cutOffAngle"_n);
    }
    // Area light hints (docs/rendering.md, Soft light with error bounds): each only on the light
    // type it fits.
    if (const NodeId metadata = node(id, "metadata"_n); metadata != kNullNode) {
        const sg::Hints h = read_hints(tree_, metadata, diagnostics_);
        const bool directional = l.type == sg::LightType::Directional;
        if (h.source_radius >= 0.0 && !directional) l.source_radius = h.source_radius;
        if (h.angular_radius >= 0.0 && directional) l.angular_radius = h.angular_radius;
        if ((h.source_radius >= 0.0 && directional) || (h.angular_radius >= 0.0 && !directional))
            warn(id, "hint:area",
                 directional ? "sourceRadius is for PointLight and SpotLight; ignored"
                             : "angularRadius is for DirectionalLight; ignored");
    }
    const sg::Index index = static_cast<sg::Index>(scene_.lights.size());
    scene_.lights.push_back(std::move(l));
    return index;
}

sg::Index Builder::make_viewpoint(NodeId id) {
    sg::Viewpoint v;
    v.origin = origin(id);
    v.def_name = std::string(tree_.def_name(id));
    v.ortho = tree_.type_name(id) == "OrthoViewpoint";
    v.position = vec3(id, "position"_n);
    v.orientation = rotation(id, "orientation"_n);
    if (type(id) == "GeoViewpoint"_n) read_geo_viewpoint(id, v);
    const std::vector<std::string> description = strings(id, "description"_n);
    if (!description.empty()) v.description = description[0];
    if (v.ortho) {
        FieldView fov = read(id, "fieldOfView"_n, Many::MF, {ValueKind::Float});
        if (fov.numbers.size() < 4) {
            if (!fov.numbers.empty())
                warn(id, "field-of-view",
                     "fieldOfView needs 4 numbers (min x, min y, max x, max y); using -1 -1 1 1");
            fov = default_of(type(id), "fieldOfView"_n);
        }
        for (int i = 0; i < 4; ++i) v.ortho_extent[i] = fov.numbers[i];
        // Unused for an orthographic view: a Viewpoint's default.
        v.field_of_view = default_of("Viewpoint"_n, "fieldOfView"_n).numbers[0];
    } else {
        v.field_of_view = number(id, "fieldOfView"_n);
        if (!(v.field_of_view > 0.0 && v.field_of_view < kPi)) {
            // Every value in (0, pi) is a camera, however narrow (docs/manual.md, Camera). Outside,
            // pi or more is taken as the widest sensible view; 0, negative or NaN as the default.
            const double given = v.field_of_view;
            v.field_of_view =
                given >= kPi ? kPi - 0.01 : default_of("Viewpoint"_n, "fieldOfView"_n).numbers[0];
            warn(id, "field-of-view",
                 "fieldOfView " + format_g(given) + " lies outside (0, pi); using " +
                     format_g(v.field_of_view));
        }
    }
    const sg::Index index = static_cast<sg::Index>(scene_.viewpoints.size());
    scene_.viewpoints.push_back(std::move(v));
    return index;
}

sg::Index Builder::make_background(NodeId id) {
    sg::Background b;
    b.origin = origin(id);
    b.sky_color = vec3s(id, "skyColor"_n);
    b.sky_angle = numbers(id, "skyAngle"_n);
    b.ground_color = vec3s(id, "groundColor"_n);
    b.ground_angle = numbers(id, "groundAngle"_n);
    // n colours need n - 1 angles (VRML97 6.5); the surplus of either goes.
    if (b.sky_color.empty()) b.sky_color.push_back(Vec3(0.0));
    if (b.sky_angle.size() + 1 != b.sky_color.size()) {
        warn(id, "angles",
             "skyColor needs one value more than skyAngle; the extra values are ignored");
        const size_t k = std::min(b.sky_angle.size(), b.sky_color.size() - 1);
        b.sky_angle.resize(k);
        b.sky_color.resize(k + 1);
    }
    if (!b.ground_color.empty() && b.ground_angle.size() + 1 != b.ground_color.size()) {
        warn(id, "angles",
             "groundColor needs one value more than groundAngle; the extra values are ignored");
        const size_t k = std::min(b.ground_angle.size(), b.ground_color.size() - 1);
        b.ground_angle.resize(k);
        b.ground_color.resize(k + 1);
    }
    const Name urls[6] = {"frontUrl"_n, "backUrl"_n, "leftUrl"_n,
                          "rightUrl"_n, "topUrl"_n,  "bottomUrl"_n};
    for (int i = 0; i < 6; ++i) b.urls[i] = strings(id, urls[i]);
    b.from_file = file_of(id);
    const sg::Index index = static_cast<sg::Index>(scene_.backgrounds.size());
    scene_.backgrounds.push_back(std::move(b));
    return index;
}

sg::Index Builder::make_fog(NodeId id) {
    sg::Fog f;
    f.origin = origin(id);
    f.color = vec3(id, "color"_n);
    f.visibility_range = number(id, "visibilityRange"_n);
    const std::vector<std::string> kind = strings(id, "fogType"_n);
    if (!kind.empty()) {
        if (kind[0] == "EXPONENTIAL")
            f.exponential = true;
        else if (kind[0] != "LINEAR")
            warn(id, "fog-type",
                 "fogType '" + kind[0] + "' is neither LINEAR nor EXPONENTIAL; using LINEAR");
    }
    const sg::Index index = static_cast<sg::Index>(scene_.fogs.size());
    scene_.fogs.push_back(std::move(f));
    return index;
}

sg::Index Builder::make_navigation_info(NodeId id) {
    sg::NavigationInfo info;
    info.origin = origin(id);
    info.headlight = boolean(id, "headlight"_n);
    const sg::Index index = static_cast<sg::Index>(scene_.navigation_infos.size());
    scene_.navigation_infos.push_back(std::move(info));
    return index;
}

}  // namespace detail

namespace {
FragmentStore* fragments_of(const LoadedScene& loaded) {
    if (loaded.consumed_pieces.empty()) return nullptr;
    auto* fragments = dynamic_cast<FragmentStore*>(loaded.piece_consumer.get());
    if (!fragments) throw std::logic_error("consumed pieces without their scene fragments");
    return fragments;
}
}  // namespace

std::optional<Scene> build_fragment(const NodeTree& tree, std::span<const NodeId> roots,
                                    Diagnostics& diagnostics) {
    static const LoadedScene kNothingElse;  // a fragment's nodes read nothing but `tree`
    detail::Builder builder(kNothingElse, tree, diagnostics);
    Scene scene = builder.build(roots);
    if (!builder.misreads().empty()) return std::nullopt;
    return scene;
}

Scene build_scene(const LoadedScene& loaded, Diagnostics& diagnostics) {
    detail::Builder builder(loaded, diagnostics);
    builder.fragments_ = fragments_of(loaded);
    return builder.build();
}

Scene build_scene_releasing_tree(LoadedScene& loaded, Diagnostics& diagnostics) {
    Scene scene;
    {
        detail::Builder builder(loaded, diagnostics);
        detail::TreeRelease release(loaded.tree, builder.has_shared_nodes());
        builder.release_ = &release;
        builder.fragments_ = fragments_of(loaded);
        builder.free_fragments_ = true;
        scene = builder.build();
    }
    loaded.tree = NodeTree{};  // parts of it read as zeros now
    loaded.consumed_pieces.clear();
    loaded.piece_consumer.reset();
    return scene;
}

}  // namespace vr
