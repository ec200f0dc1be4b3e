#include "scene/fragments.h"

#include <algorithm>
#include <bit>

#include "scene/plain_piece.h"

namespace vr {

namespace {

// The node types whose build reads nothing but the node tree (no source file, URL or X3D version
// of the loaded scene, which the main thread is still filling) and whose typed nodes the splice
// knows how to renumber.
bool buildable_on_its_own(const NodeTree& tree) {
    static const Name kTypes[] = {intern("Transform"),  intern("Group"),    intern("Shape"),
                                  intern("Appearance"), intern("Material"), intern("Sphere"),
                                  intern("Box"),        intern("Cylinder"), intern("Cone")};
    for (size_t k = 1; k < tree.kinds.size(); ++k)
        if (std::find(std::begin(kTypes), std::end(kTypes), tree.kinds[k].type) == std::end(kTypes))
            return false;
    return true;
}

// USEs of DEFs before the piece (outer nodes) only as a Shape's appearance, the pattern of
// exporters that DEF an Appearance once and USE it for every atom: the splice looks those up in
// the scene being built. Anywhere else the fragment would lack the node.
bool outer_uses_are_appearances(const NodeTree& tree, std::span<const NodeId> roots) {
    static const Name kShape = intern("Shape"), kAppearance = intern("appearance");
    size_t outer = 0, as_appearance = 0;
    for (NodeId r : tree.node_refs) outer += is_outer_node(r);
    for (NodeId r : roots)
        if (is_outer_node(r)) return false;
    if (outer == 0) return true;
    for (NodeId id = 0; id < tree.nodes.size(); ++id) {
        if (tree.type(id) != kShape) continue;
        for (const FieldEntry& e : tree.set_fields(id))
            if (e.name == kAppearance && e.type.kind == ValueKind::Node && e.count == 1)
                as_appearance += is_outer_node(tree.node_refs[e.begin]);
    }
    return outer == as_appearance;
}

// What the splice renumbers, and nothing else: no lights, bindable nodes, textures, hints,
// billboards or Inline contents, and every geometry one of the four primitives.
bool splicable(const Scene& s) {
    if (!s.textures.empty() || !s.lights.empty() || !s.viewpoints.empty() ||
        !s.backgrounds.empty() || !s.fogs.empty() || !s.navigation_infos.empty() ||
        !s.hints.empty() || !s.billboard_axes.empty())
        return false;
    for (const sg::Group& g : s.groups)
        if (g.inline_content || g.billboard()) return false;
    return only_plain_primitives(s);
}

}  // namespace

bool only_plain_primitives(const Scene& s) {
    for (const sg::Geometry& g : s.geometries)
        if (!std::holds_alternative<sg::Sphere>(g.shape) &&
            !std::holds_alternative<sg::Box>(g.shape) &&
            !std::holds_alternative<sg::Cylinder>(g.shape) &&
            !std::holds_alternative<sg::Cone>(g.shape))
            return false;
    return true;
}

bool SceneFragments::consume(size_t piece, const NodeTree& tree, std::span<const NodeId> roots) {
    if (!buildable_on_its_own(tree) || !outer_uses_are_appearances(tree, roots)) return false;
    Diagnostics diagnostics;
    std::optional<Scene> scene = build_fragment(tree, roots, diagnostics);
    if (!scene || !diagnostics.all().empty() || !splicable(*scene)) return false;
    auto built = std::make_unique<Scene>(std::move(*scene));
    std::lock_guard lock(mutex_);
    built_[piece] = std::move(built);
    return true;
}

std::optional<TextConsumed> SceneFragments::consume_text(size_t piece, const PieceText& text) {
    std::optional<PlainPiece> plain = read_plain_piece(text);
    if (!plain) return std::nullopt;
    auto built = std::make_unique<Scene>(std::move(plain->fragment));
    ++text_pieces_;
    std::lock_guard lock(mutex_);
    built_[piece] = std::move(built);
    return std::move(plain->counts);
}

void SceneFragments::discard(size_t piece) {
    std::unique_ptr<Scene> gone;  // freed outside the lock
    std::lock_guard lock(mutex_);
    if (auto it = built_.find(piece); it != built_.end()) {
        gone = std::move(it->second);
        built_.erase(it);
    }
}

Scene* SceneFragments::fragment(size_t piece) {
    std::lock_guard lock(mutex_);
    const auto it = built_.find(piece);
    return it == built_.end() ? nullptr : it->second.get();
}

}  // namespace vr
