// The scene build's part that takes in a fragment built from one piece of the file while it was
// read (build.h: FragmentStore; src/scene/fragments.h builds them).
#include <algorithm>
#include <bit>
#include <iterator>

#include "scene/build_internal.h"

namespace vr {
namespace detail {

namespace {

// A fragment's array without its first `front` elements (its root's group or child block, which
// the scene has in its own root): taken when `take`, else copied.
template <class T>
std::vector<T> without_front(ChunkedArray<T>& chunks, size_t front, bool take) {
    std::vector<T> v;
    if (take) {
        v = std::move(chunks).take_all();
        v.erase(v.begin(), v.begin() + std::ptrdiff_t(std::min(front, v.size())));
    } else {
        v.assign(std::next(chunks.begin(), std::ptrdiff_t(front)), chunks.end());
    }
    return v;
}

}  // namespace

// Adds fragment `f` (built by a Builder of its own from one piece) to the scene being built, as if
// its top-level nodes had been built here, in file order: its root's children go to the root's
// block from `root_count` on; its other groups, child blocks, translations and shapes become
// chunks of the scene, renumbered by the sizes so far; its materials, appearances and spheres meet
// the same merge maps the tree's do. So the arrays equal the sequential build's, index by index.
void Builder::splice(Scene& f, const ConsumedPiece& piece, size_t root_first, size_t& root_count) {
    const uint32_t read_roots = piece.roots;
    const bool take = free_fragments_;
    const auto group_base =
        static_cast<uint32_t>(scene_.groups.size() - 1);  // f's root is not kept
    const auto shape_base = static_cast<uint32_t>(scene_.shapes.size());
    const auto translated_base = static_cast<uint32_t>(scene_.translated_shapes.size());
    const auto translation_base = static_cast<uint32_t>(scene_.translations.size());
    const auto matrix_base = static_cast<uint32_t>(scene_.matrices.size());
    // f's child blocks after its root's (one slot per top-level node read) follow ours.
    const auto ref_base = static_cast<int64_t>(scene_.child_refs.size()) - read_roots;

    std::vector<sg::Index> material(f.materials.size()), appearance(f.appearances.size()),
        geometry(f.geometries.size());
    for (size_t i = 0; i < f.materials.size(); ++i) {
        const sg::Material& m = f.materials[i];
        MaterialKey key;
        sg::Index index = static_cast<sg::Index>(scene_.materials.size());
        if (material_key(m, key)) index = same_material_.try_emplace(key, index).first->second;
        if (index == scene_.materials.size()) scene_.materials.push_back(m);
        material[i] = index;
    }
    for (size_t i = 0; i < f.appearances.size(); ++i) {
        sg::Appearance a = f.appearances[i];
        if (a.material != sg::kNone) a.material = material[a.material];
        sg::Index index = static_cast<sg::Index>(scene_.appearances.size());
        if (uint64_t key; appearance_key(a, key)) index = same_appearance_.find_or_add(key, index);
        if (index == scene_.appearances.size()) scene_.appearances.push_back(a);
        appearance[i] = index;
    }
    for (size_t i = 0; i < f.geometries.size(); ++i) {
        const sg::Geometry& g = f.geometries[i];
        sg::Index index = static_cast<sg::Index>(scene_.geometries.size());
        const auto* sphere = std::get_if<sg::Sphere>(&g.shape);
        if (sphere && g.hints == sg::kNone)
            index = (g.cull_back_faces ? same_solid_sphere_ : same_sphere_)
                        .find_or_add(std::bit_cast<uint64_t>(sphere->radius), index);
        if (index == scene_.geometries.size()) {
            sg::Geometry copy;  // only the four primitives (splicable): plain values
            copy.origin = g.origin;
            copy.hints = g.hints;
            copy.cull_back_faces = g.cull_back_faces;
            std::visit(
                [&copy](const auto& shape) {
                    using T = std::decay_t<decltype(shape)>;
                    if constexpr (std::is_copy_constructible_v<T>) copy.shape = shape;
                },
                g.shape);
            scene_.geometries.push_back(std::move(copy));
        }
        geometry[i] = index;
    }
    scene_.matrices.insert(scene_.matrices.end(), f.matrices.begin(), f.matrices.end());

    const auto renumber = [&](sg::ChildRef r) {  // unused slots (kNone) stay unused
        if (r.index != sg::kNone)
            r.index += r.kind == sg::NodeKind::Group   ? group_base
                       : r.kind == sg::NodeKind::Shape ? shape_base
                                                       : translated_base;
        return r;
    };
    const sg::Group root = f.groups[Scene::kRoot];
    for (uint32_t i = 0; i < root.child_count; ++i)
        scene_.child_refs[root_first + root_count++] = renumber(f.child_refs[root.first_child + i]);

    std::vector<sg::Group> groups = without_front(f.groups, 1, take);
    for (sg::Group& g : groups) {
        g.first_child = static_cast<uint32_t>(g.first_child + ref_base);
        if (g.transform_kind == sg::GroupTransform::Translation)
            g.transform += translation_base;
        else if (g.transform_kind == sg::GroupTransform::Matrix)
            g.transform += matrix_base;
    }
    std::vector<sg::ChildRef> refs = without_front(f.child_refs, read_roots, take);
    for (sg::ChildRef& r : refs) r = renumber(r);
    const auto renumber_shape = [&](auto& s) {  // sg::Shape or sg::TranslatedShape
        if (is_outer_node(s.appearance)) {
            // An Appearance DEF'd before the piece: built with the tree's nodes before this
            // fragment (the shared node's memo gives its index). Only one DEF'd where nothing
            // builds it (an inactive Switch choice) is built first here, its material and
            // appearance then numbered after this fragment's own: the same scene, other indices.
            const NodeId node = piece.outer_nodes[s.appearance - kFirstOuterNode];
            s.appearance = node == kNullNode ? sg::kNone : this->appearance(node);
        } else if (s.appearance != sg::kNone) {
            s.appearance = appearance[s.appearance];
        }
        if (s.geometry != sg::kNone) s.geometry = geometry[s.geometry];
    };
    std::vector<sg::Shape> shapes = without_front(f.shapes, 0, take);
    for (sg::Shape& s : shapes) renumber_shape(s);
    std::vector<sg::TranslatedShape> translated = without_front(f.translated_shapes, 0, take);
    for (sg::TranslatedShape& t : translated) renumber_shape(t);
    scene_.groups.adopt(std::move(groups));
    scene_.child_refs.adopt(std::move(refs));
    scene_.translations.adopt(without_front(f.translations, 0, take));
    scene_.shapes.adopt(std::move(shapes));
    scene_.translated_shapes.adopt(std::move(translated));
}

}  // namespace detail
}  // namespace vr
