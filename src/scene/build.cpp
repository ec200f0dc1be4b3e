// Node tree -> typed scene: grouping nodes, Shape/Appearance/Material/textures, lights and bindable
// nodes. Geometry nodes are in build_geometry.cpp.
#include "scene/build.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <unordered_map>

#include "scene/build_internal.h"
#include "scene/hints.h"
#include "core/format.h"
#include "core/huge_pages.h"
#include "scene/report.h"
#include "scene/transform.h"

namespace vr {
namespace detail {

const Names& names() {
    static const Names n;
    return n;
}

namespace {

enum class ChildKind : uint8_t {
    Group,
    Transform,
    Billboard,
    Switch,
    LOD,
    Inline,
    CADFace,
    Shape,
    Light,
    Viewpoint,
    Background,
    Fog,
    NavigationInfo,
    Silent,
    NotModelled,
};

ChildKind child_kind(Name type) {
    static const std::unordered_map<Name, ChildKind> table = [] {
        std::unordered_map<Name, ChildKind> t;
        for (const char* n : {"Group", "StaticGroup", "Collision", "Anchor", "CADAssembly",
                              "CADLayer", "PickableGroup", "ViewpointGroup"})
            t[intern(n)] = ChildKind::Group;
        for (const char* n : {"Transform", "CADPart"}) t[intern(n)] = ChildKind::Transform;
        t[intern("Billboard")] = ChildKind::Billboard;
        t[intern("Switch")] = ChildKind::Switch;
        t[intern("LOD")] = ChildKind::LOD;
        t[intern("Inline")] = ChildKind::Inline;
        t[intern("CADFace")] = ChildKind::CADFace;
        t[intern("Shape")] = ChildKind::Shape;
        for (const char* n : {"DirectionalLight", "PointLight", "SpotLight"})
            t[intern(n)] = ChildKind::Light;
        for (const char* n : {"Viewpoint", "OrthoViewpoint"}) t[intern(n)] = ChildKind::Viewpoint;
        t[intern("Background")] = ChildKind::Background;
        t[intern("Fog")] = ChildKind::Fog;
        t[intern("NavigationInfo")] = ChildKind::NavigationInfo;
        // Nodes that draw nothing at time 0 (SPEC section 2: parsed and ignored).
        for (const char* n :
             {"WorldInfo",       "Script",          "Sound",         "AudioClip",
              "MetadataSet",     "MetadataString",  "MetadataFloat", "MetadataDouble",
              "MetadataInteger", "MetadataBoolean", "BooleanToggle", "IntegerTrigger",
              "TimeTrigger",     "BooleanTrigger",  "FontStyle",     "ScreenFontStyle",
              "EspduTransform",  "SignalPdu",       "ReceiverPdu",   "TransmitterPdu"})
            t[intern(n)] = ChildKind::Silent;
        return t;
    }();
    const auto it = table.find(type);
    if (it != table.end()) return it->second;
    const std::string_view text = name_text(type);
    for (std::string_view suffix :
         {"Sensor", "Interpolator", "Sequencer", "Trigger", "Filter", "Chaser", "Damper"})
        if (text.size() > suffix.size() && text.substr(text.size() - suffix.size()) == suffix)
            return ChildKind::Silent;
    return ChildKind::NotModelled;
}

}  // namespace

// ------------------------------------------------------------------------------------------------
// Field readers

double Builder::number(NodeId n, Name f, double fallback) const {
    const FieldView v = tree_.get(n, f);
    return v.numbers.empty() ? fallback : v.numbers[0];
}
int32_t Builder::integer(NodeId n, Name f, int32_t fallback) const {
    const FieldView v = tree_.get(n, f);
    return v.numbers.empty() ? fallback : static_cast<int32_t>(v.numbers[0]);
}
bool Builder::boolean(NodeId n, Name f, bool fallback) const {
    const FieldView v = tree_.get(n, f);
    return v.numbers.empty() ? fallback : v.numbers[0] != 0.0;
}
Vec2 Builder::vec2(NodeId n, Name f, Vec2 fallback) const {
    const FieldView v = tree_.get(n, f);
    return v.numbers.size() < 2 ? fallback : Vec2(v.numbers[0], v.numbers[1]);
}
Vec3 Builder::vec3(NodeId n, Name f, Vec3 fallback) const {
    const FieldView v = tree_.get(n, f);
    return v.numbers.size() < 3 ? fallback : Vec3(v.numbers[0], v.numbers[1], v.numbers[2]);
}
Vec4 Builder::rotation(NodeId n, Name f) const {
    const FieldView v = tree_.get(n, f);
    if (v.numbers.size() < 4) return Vec4(0.0, 0.0, 1.0, 0.0);
    return Vec4(v.numbers[0], v.numbers[1], v.numbers[2], v.numbers[3]);
}
std::vector<double> Builder::numbers(NodeId n, Name f) const {
    const FieldView v = tree_.get(n, f);
    return {v.numbers.begin(), v.numbers.end()};
}
std::vector<int32_t> Builder::integers(NodeId n, Name f) const {
    const FieldView v = tree_.get(n, f);
    std::vector<int32_t> out(v.numbers.size());
    for (size_t i = 0; i < out.size(); ++i) {
        const double d = v.numbers[i];
        // Out-of-int32 values cannot be valid indices; -2 is rejected by every index check.
        out[i] = d >= -2147483648.0 && d <= 2147483647.0 ? static_cast<int32_t>(d) : -2;
    }
    return out;
}
std::vector<Vec2> Builder::vec2s(NodeId n, Name f) const {
    const FieldView v = tree_.get(n, f);
    std::vector<Vec2> out(v.numbers.size() / 2);
    for (size_t i = 0; i < out.size(); ++i) out[i] = Vec2(v.numbers[2 * i], v.numbers[2 * i + 1]);
    return out;
}
std::vector<Vec3> Builder::vec3s(NodeId n, Name f) const {
    const FieldView v = tree_.get(n, f);
    const size_t stride = v.type.kind == ValueKind::ColorRGBA || v.type.kind == ValueKind::Vec4f ||
                                  v.type.kind == ValueKind::Vec4d
                              ? 4
                              : 3;
    std::vector<Vec3> out(v.numbers.size() / stride);
    for (size_t i = 0; i < out.size(); ++i)
        out[i] = Vec3(v.numbers[stride * i], v.numbers[stride * i + 1], v.numbers[stride * i + 2]);
    return out;
}
std::vector<std::string> Builder::strings(NodeId n, Name f) const {
    const FieldView v = tree_.get(n, f);
    return {v.strings.begin(), v.strings.end()};
}
NodeId Builder::node(NodeId n, Name f) const {
    const FieldView v = tree_.get(n, f);
    return v.nodes.empty() ? kNullNode : v.nodes[0];
}
std::span<const NodeId> Builder::nodes(NodeId n, Name f) const { return tree_.get(n, f).nodes; }

sg::Origin Builder::origin(NodeId n) const {
    const Node& node = tree_.nodes[n];
    return sg::Origin{tree_.type(n), node.def_name, node.loc};
}

sg::Index Builder::hints(NodeId n) {
    const NodeId metadata = node(n, names().metadata);
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
    : loaded_(loaded), tree_(loaded.tree), diagnostics_(diagnostics) {
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
    memo_.reserve(shared);
}

size_t Builder::KeyHash::operator()(const MaterialKey& key) const {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (uint64_t k : key) {
        h ^= k + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
        h *= 0xBF58476D1CE4E5B9ull;
    }
    return size_t(h ^ (h >> 31));
}

Scene Builder::build() {
    reserve();
    scene_.main_file = loaded_.main_file;
    scene_.allowed_roots = loaded_.allowed_roots;
    scene_.groups.emplace_back();  // the root
    scene_.groups[Scene::kRoot].origin.type = intern("(root)");
    add_children(Scene::kRoot, tree_.roots);
    return std::move(scene_);
}

void Builder::reserve() {
    // Arenas sized from the node counts up front: PyMOL files hold 1e5 shapes, and growing the
    // arenas by doubling would move (and touch) every element several times. Appearances,
    // materials and geometries are mostly merged (see same_material_): they grow as needed.
    const Names& n = names();
    size_t groups = 1, shapes = 0, transforms = 0;
    for (const Node& node : tree_.nodes) {
        const Name t = tree_.kinds[node.kind].type;
        if (t == n.Shape) {
            ++shapes;
            continue;
        }
        // The most common nodes besides groups, told apart without child_kind's suffix checks.
        if (t == n.Appearance || t == n.Material || is_geometry_type(t)) continue;
        const ChildKind kind = child_kind(t);
        if (kind <= ChildKind::CADFace) ++groups;
        if (kind == ChildKind::Transform) ++transforms;
    }
    reserve_huge(scene_.groups, groups);
    reserve_huge(scene_.shapes, shapes);
    reserve_huge(scene_.translations, transforms);
    // Every child is a reference in the tree: an upper bound (pages past the end stay untouched).
    size_t refs = tree_.node_refs.size() + tree_.roots.size();
    for (const auto& [inline_node, roots] : tree_.inline_roots) refs += roots.size();
    reserve_huge(scene_.child_refs, refs);
}

void Builder::add_children(sg::Index group, std::span<const NodeId> children) {
    // The group's block is claimed before its children are built (child groups append theirs
    // after it) and filled from the front; children that draw nothing leave unused slots at its
    // end, which cost less than building the list elsewhere and copying it.
    const size_t first = scene_.child_refs.size();
    scene_.child_refs.resize(first + children.size());
    size_t count = 0;
    for (NodeId id : children) {
        if (id == kNullNode || id >= tree_.nodes.size()) continue;
        if (const auto ref = child(id)) scene_.child_refs[first + count++] = *ref;
    }
    sg::Group& g = scene_.groups[group];
    g.first_child = static_cast<uint32_t>(first);
    g.child_count = static_cast<uint32_t>(count);
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
    switch (child_kind(type(id))) {
        case ChildKind::Group:
        case ChildKind::Transform:
        case ChildKind::Billboard:
        case ChildKind::Switch:
        case ChildKind::LOD:
        case ChildKind::Inline:
        case ChildKind::CADFace:
            return sg::ChildRef{NodeKind::Group, make_group(id)};
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
    const Names& n = names();
    const sg::Index index = static_cast<sg::Index>(scene_.groups.size());
    scene_.groups.emplace_back();
    sg::Group group;
    group.origin = origin(id);
    std::span<const NodeId> children;
    std::vector<NodeId> chosen;  // Switch/LOD: the one active child
    switch (child_kind(type(id))) {
        case ChildKind::Transform: {
            TransformFields f;
            f.translation = vec3(id, n.translation, f.translation);
            f.rotation = rotation(id, n.rotation);
            f.scale = vec3(id, n.scale, f.scale);
            f.scale_orientation = rotation(id, n.scale_orientation);
            f.center = vec3(id, n.center, f.center);
            const Mat4 m = transform_matrix(f);
            if (is_singular(m)) {
                group.singular = true;  // flattening skips the subtree: no matrix to keep
                warn(id, "singular",
                     all_finite(m)
                         ? "has a singular transform (a zero scale); its children are skipped"
                         : "has a NaN or infinite transform value; its children are skipped");
            } else if (is_translation(m)) {
                group.transform_kind = sg::GroupTransform::Translation;
                group.transform = static_cast<sg::Index>(scene_.translations.size());
                scene_.translations.push_back(Vec3(m[3]));
            } else {
                group.transform_kind = sg::GroupTransform::Matrix;
                group.transform = static_cast<sg::Index>(scene_.matrices.size());
                scene_.matrices.push_back(m);
            }
            children = nodes(id, n.children);
            break;
        }
        case ChildKind::Billboard:
            group.transform_kind = sg::GroupTransform::Billboard;
            group.transform = static_cast<sg::Index>(scene_.billboard_axes.size());
            scene_.billboard_axes.push_back(vec3(id, n.axis_of_rotation, Vec3(0.0, 1.0, 0.0)));
            children = nodes(id, n.children);
            break;
        case ChildKind::Switch: {
            // VRML97 `choice`, X3D `children`: the reader accepts both spellings, so take the one
            // that is set.
            const std::span<const NodeId> choice = nodes(id, n.choice);
            const std::span<const NodeId> all = !choice.empty() ? choice : nodes(id, n.children);
            const int32_t which = integer(id, n.which_choice, -1);
            if (which >= 0 && static_cast<size_t>(which) < all.size()) chosen.push_back(all[which]);
            children = chosen;
            break;
        }
        case ChildKind::LOD: {
            const std::span<const NodeId> level =
                nodes(id, n.level);  // VRML97 `level`, X3D `children`
            const std::span<const NodeId> all = !level.empty() ? level : nodes(id, n.children);
            if (!all.empty()) chosen.push_back(all[0]);
            children = chosen;
            break;
        }
        case ChildKind::Inline: {
            group.inline_content = true;
            const auto it = tree_.inline_roots.find(id);
            if (it != tree_.inline_roots.end() && boolean(id, n.load, true)) children = it->second;
            break;
        }
        case ChildKind::CADFace:
            chosen.push_back(node(id, n.shape));
            children = chosen;
            break;
        default:
            children = nodes(id, n.children);
            break;
    }
    scene_.groups[index] = group;
    add_children(index, children);
    return index;
}

std::optional<sg::ChildRef> Builder::make_shape(NodeId id) {
    const Names& n = names();
    if (!boolean(id, n.visible, true)) return std::nullopt;  // X3D 4 Shape.visible
    sg::Shape shape;
    shape.origin = origin(id);
    shape.hints = hints(id);
    const NodeId app = node(id, n.appearance);
    if (app != kNullNode) shape.appearance = appearance(app);
    const NodeId geo = node(id, n.geometry);
    if (geo != kNullNode) shape.geometry = geometry(geo);
    if (shape.geometry == sg::kNone) return std::nullopt;
    const sg::Index index = static_cast<sg::Index>(scene_.shapes.size());
    scene_.shapes.push_back(std::move(shape));
    return sg::ChildRef{sg::NodeKind::Shape, index};
}

// ------------------------------------------------------------------------------------------------
// Appearance

sg::Index Builder::appearance(NodeId id) {
    const Names& n = names();
    Memo* memo = shared(id);
    if (memo && memo->typed != sg::kNone) return memo->typed;
    if (type(id) != n.Appearance) {
        warn(id, "wrong-type",
             "cannot be an appearance; the shape is drawn with the default appearance");
        return sg::kNone;
    }
    sg::Appearance a;
    a.origin = origin(id);
    if (const NodeId m = node(id, n.material); m != kNullNode) a.material = material(m);
    if (const NodeId t = node(id, n.texture); t != kNullNode) a.texture = texture(t);
    if (a.texture == sg::kNone && a.material != sg::kNone) {
        // X3D 4: a texture may sit in the material instead (Material.diffuseTexture,
        // PhysicalMaterial.baseTexture, UnlitMaterial.emissiveTexture); it stands in for the
        // Appearance's texture (the materials' other texture fields are not modelled).
        const NodeId m = node(id, n.material);
        const Name field = type(m) == n.PhysicalMaterial ? n.base_texture
                           : type(m) == n.UnlitMaterial  ? n.emissive_texture
                                                         : n.diffuse_texture;
        if (const NodeId t = node(m, field); t != kNullNode) a.texture = texture(t);
    }
    if (const NodeId tt = node(id, n.texture_transform); tt != kNullNode)
        read_texture_transform(tt, a);
    sg::Index index = static_cast<sg::Index>(scene_.appearances.size());
    if (!a.has_texture_transform) {
        const uint64_t key = (uint64_t(a.material) << 32) | a.texture;
        index = same_appearance_.find_or_add(key, index);
    }
    if (index == scene_.appearances.size()) scene_.appearances.push_back(std::move(a));
    if ((memo = shared(id))) memo->typed = index;
    return index;
}

sg::Index Builder::material(NodeId id) {
    const Names& n = names();
    if (Memo* memo = shared(id); memo && memo->typed != sg::kNone) return memo->typed;
    sg::Material m;
    m.origin = origin(id);
    const Name t = type(id);
    if (t == n.Material || t == n.TwoSidedMaterial) {
        // TwoSidedMaterial: its front-face fields (the back ones are not modelled).
        m.model = sg::MaterialModel::Phong;
        m.ambient_intensity = number(id, n.ambient_intensity, m.ambient_intensity);
        m.diffuse_color = vec3(id, n.diffuse_color, m.diffuse_color);
        m.specular_color = vec3(id, n.specular_color, m.specular_color);
        m.shininess = number(id, n.shininess, m.shininess);
    } else if (t == n.PhysicalMaterial) {
        m.model = sg::MaterialModel::Physical;
        m.diffuse_color = vec3(id, n.base_color, m.diffuse_color);
        m.metallic = number(id, n.metallic, m.metallic);
        m.roughness = number(id, n.roughness, m.roughness);
    } else if (t == n.UnlitMaterial) {
        m.model = sg::MaterialModel::Unlit;
    } else {
        warn(id, "wrong-type", "cannot be a material; the shape is unlit");
        return sg::kNone;
    }
    m.emissive_color = vec3(id, n.emissive_color, m.emissive_color);
    m.transparency = number(id, n.transparency, m.transparency);
    m.hints = hints(id);
    sg::Index index = static_cast<sg::Index>(scene_.materials.size());
    const double values[] = {m.diffuse_color.x,  m.diffuse_color.y,  m.diffuse_color.z,
                             m.specular_color.x, m.specular_color.y, m.specular_color.z,
                             m.emissive_color.x, m.emissive_color.y, m.emissive_color.z,
                             m.ambient_intensity, m.shininess,       m.transparency,
                             m.metallic,          m.roughness};
    bool mergeable = m.hints == sg::kNone;  // hints belong to their node
    MaterialKey key{uint64_t(m.model)};
    for (size_t i = 0; i < std::size(values); ++i) {
        mergeable = mergeable && std::isfinite(values[i]);  // warned per node by flattening
        key[i + 1] = std::bit_cast<uint64_t>(values[i]);
    }
    if (mergeable) index = same_material_.try_emplace(key, index).first->second;
    if (index == scene_.materials.size()) scene_.materials.push_back(std::move(m));
    if (Memo* memo = shared(id)) memo->typed = index;
    return index;
}

sg::Index Builder::texture(NodeId id) {
    const Names& n = names();
    if (Memo* memo = shared(id); memo && memo->typed != sg::kNone) return memo->typed;
    const Name t = type(id);
    if (t == n.MultiTexture) {
        // The first texture stands for the stack (multi-texturing is not modelled).
        for (NodeId inner : nodes(id, n.texture))
            if (inner != kNullNode && type(inner) != n.MultiTexture) {
                const sg::Index index = texture(inner);
                if (Memo* memo = shared(id)) memo->typed = index;
                return index;
            }
        return sg::kNone;
    }
    sg::Texture tex;
    tex.origin = origin(id);
    tex.repeat_s = boolean(id, n.repeat_s, true);
    tex.repeat_t = boolean(id, n.repeat_t, true);
    if (t == n.ImageTexture) {
        tex.kind = sg::TextureKind::Image;
        tex.urls = strings(id, n.url);
        tex.from_file = file_of(id);
        if (tex.urls.empty()) return sg::kNone;
    } else if (t == n.PixelTexture) {
        tex.kind = sg::TextureKind::Pixel;
        const FieldView image = tree_.get(id, n.image);
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
    const Names& n = names();
    if (type(id) == n.MultiTextureTransform) {
        const auto inner = nodes(id, n.texture_transform);
        if (!inner.empty() && inner[0] != kNullNode && type(inner[0]) == n.TextureTransform)
            read_texture_transform(inner[0], a);
        return;
    }
    if (type(id) != n.TextureTransform) {
        warn(id, "wrong-type", "cannot be a texture transform; ignored");
        return;
    }
    a.has_texture_transform = true;
    sg::TextureTransform& tt = a.texture_transform;
    tt.center = vec2(id, n.center, tt.center);
    tt.rotation = number(id, n.rotation, tt.rotation);
    tt.scale = vec2(id, n.scale, tt.scale);
    tt.translation = vec2(id, n.translation, tt.translation);
}

// ------------------------------------------------------------------------------------------------
// Lights and bindable nodes

sg::Index Builder::make_light(NodeId id) {
    const Names& n = names();
    sg::Light l;
    l.origin = origin(id);
    const std::string_view t = tree_.type_name(id);
    l.type = t == "DirectionalLight" ? sg::LightType::Directional
             : t == "PointLight"     ? sg::LightType::Point
                                     : sg::LightType::Spot;
    l.on = boolean(id, n.on, true);
    // VRML97 has no `global` field; the X3D defaults (FALSE for directional, TRUE for point and
    // spot lights) are exactly VRML97's scoping rules, and the reader gives them for .wrl files
    // too.
    l.global = boolean(id, n.global, l.type != sg::LightType::Directional);
    l.color = vec3(id, n.color, l.color);
    l.intensity = number(id, n.intensity, l.intensity);
    l.ambient_intensity = number(id, n.ambient_intensity, l.ambient_intensity);
    l.direction = vec3(id, n.direction, l.direction);
    l.location = vec3(id, n.location, l.location);
    l.attenuation = vec3(id, n.attenuation, l.attenuation);
    l.radius = number(id, n.radius, l.radius);
    l.beam_width = number(id, n.beam_width, l.beam_width);
    l.cut_off_angle = number(id, n.cut_off_angle, l.cut_off_angle);
    const sg::Index index = static_cast<sg::Index>(scene_.lights.size());
    scene_.lights.push_back(std::move(l));
    return index;
}

sg::Index Builder::make_viewpoint(NodeId id) {
    const Names& n = names();
    sg::Viewpoint v;
    v.origin = origin(id);
    v.def_name = std::string(tree_.def_name(id));
    v.ortho = tree_.type_name(id) == "OrthoViewpoint";
    v.position = vec3(id, n.position, v.position);
    v.orientation = rotation(id, n.orientation);
    const std::vector<std::string> description = strings(id, n.description);
    if (!description.empty()) v.description = description[0];
    const FieldView fov = tree_.get(id, n.field_of_view);
    if (v.ortho) {
        if (fov.numbers.size() >= 4) {
            for (int i = 0; i < 4; ++i) v.ortho_extent[i] = fov.numbers[i];
        } else if (!fov.numbers.empty()) {
            warn(id, "field-of-view",
                 "fieldOfView needs 4 numbers (min x, min y, max x, max y); using -1 -1 1 1");
        }
    } else if (!fov.numbers.empty()) {
        v.field_of_view = fov.numbers[0];
        if (!(v.field_of_view > 0.0 && v.field_of_view < kPi)) {
            // Every value in (0, pi) is a camera, however narrow (SPEC section 4). Outside, pi or
            // more is taken as the widest sensible view; 0, negative or NaN as the default.
            const double given = v.field_of_view;
            v.field_of_view = given >= kPi ? kPi - 0.01 : 0.785398;
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
    const Names& n = names();
    sg::Background b;
    b.origin = origin(id);
    b.sky_color = vec3s(id, n.sky_color);
    b.sky_angle = numbers(id, n.sky_angle);
    b.ground_color = vec3s(id, n.ground_color);
    b.ground_angle = numbers(id, n.ground_angle);
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
    const Name urls[6] = {n.front_url, n.back_url, n.left_url,
                          n.right_url, n.top_url,  n.bottom_url};
    for (int i = 0; i < 6; ++i) b.urls[i] = strings(id, urls[i]);
    b.from_file = file_of(id);
    const sg::Index index = static_cast<sg::Index>(scene_.backgrounds.size());
    scene_.backgrounds.push_back(std::move(b));
    return index;
}

sg::Index Builder::make_fog(NodeId id) {
    const Names& n = names();
    sg::Fog f;
    f.origin = origin(id);
    f.color = vec3(id, n.color, f.color);
    f.visibility_range = number(id, n.visibility_range, f.visibility_range);
    const std::vector<std::string> kind = strings(id, n.fog_type);
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
    info.headlight = boolean(id, names().headlight, true);
    const sg::Index index = static_cast<sg::Index>(scene_.navigation_infos.size());
    scene_.navigation_infos.push_back(std::move(info));
    return index;
}

}  // namespace detail

Scene build_scene(const LoadedScene& loaded, Diagnostics& diagnostics) {
    detail::Builder builder(loaded, diagnostics);
    return builder.build();
}

}  // namespace vr
