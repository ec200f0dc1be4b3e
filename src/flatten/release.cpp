// flatten_scene_releasing: the typed scene's per-node chunks freed behind the walk over the root's
// children (flattener.h, "releasing the typed scene behind the walk").
#include <malloc.h>

#include <algorithm>
#include <cstdint>

#include "flatten/flattener.h"

namespace vr::flatten_detail {
namespace {

enum Array { kGroups, kShapes, kTranslations, kChildRefs, kTranslatedShapes };

template <size_t N>
void note(size_t (&lo)[N], size_t (&hi)[N], int a, size_t i) {
    lo[a] = std::min(lo[a], i);
    hi[a] = std::max(hi[a], i);
}

}  // namespace

bool Flattener::span_of(const sg::ChildRef& c, NodeSpan& span, size_t& budget) {
    span = NodeSpan{};
    if (c.kind == sg::NodeKind::Shape) {
        note(span.lo, span.hi, kShapes, c.index);
        return budget-- > 0;
    }
    if (c.kind == sg::NodeKind::TranslatedShape) {
        note(span.lo, span.hi, kTranslatedShapes, c.index);
        return budget-- > 0;
    }
    if (c.kind != sg::NodeKind::Group) return true;  // lights, bindables: plain vectors
    span_stack_.assign(1, c.index);
    while (!span_stack_.empty()) {
        if (budget == 0) return false;
        --budget;
        const sg::Index g = span_stack_.back();
        span_stack_.pop_back();
        const sg::Group& group = scene_.groups[g];
        note(span.lo, span.hi, kGroups, g);
        if (group.transform_kind == sg::GroupTransform::Translation)
            note(span.lo, span.hi, kTranslations, group.transform);
        if (group.child_count > 0) {
            note(span.lo, span.hi, kChildRefs, group.first_child);
            note(span.lo, span.hi, kChildRefs, size_t(group.first_child) + group.child_count - 1);
        }
        for (const sg::ChildRef& child : scene_.children_of(group)) {
            if (child.kind == sg::NodeKind::Group) span_stack_.push_back(child.index);
            if (child.kind == sg::NodeKind::Shape) note(span.lo, span.hi, kShapes, child.index);
            if (child.kind == sg::NodeKind::TranslatedShape)
                note(span.lo, span.hi, kTranslatedShapes, child.index);
        }
    }
    return true;
}

bool Flattener::plan_release() {
    if (releasable_ == nullptr || frame_.root != Scene::kRoot || !scene_.layers.empty())
        return false;
    // Each node once: a node shared between subtrees (USE) would take the budget twice.
    size_t budget = scene_.groups.size() + scene_.shapes.size() + scene_.translated_shapes.size();
    size_t last[kSpanArrays] = {};
    bool any[kSpanArrays] = {};
    for (const sg::ChildRef& c : scene_.children_of(scene_.groups[Scene::kRoot])) {
        NodeSpan span;
        if (!span_of(c, span, budget)) return false;
        for (int a = 0; a < kSpanArrays; ++a) {
            if (span.lo[a] == SIZE_MAX) continue;
            if (any[a] && span.lo[a] <= last[a]) return false;
            last[a] = span.hi[a];
            any[a] = true;
        }
    }
    return true;
}

void Flattener::release_before(const sg::ChildRef& next) {
    NodeSpan span;
    size_t budget = SIZE_MAX;
    span_of(next, span, budget);
    Scene& s = *releasable_;
    const sg::Group& root = scene_.groups[Scene::kRoot];
    const size_t root_children = root.child_count > 0 ? root.first_child : SIZE_MAX;
    if (span.lo[kGroups] != SIZE_MAX)
        released_bytes_ += s.groups.release_below(span.lo[kGroups], Scene::kRoot);
    if (span.lo[kShapes] != SIZE_MAX) released_bytes_ += s.shapes.release_below(span.lo[kShapes]);
    if (span.lo[kTranslations] != SIZE_MAX)
        released_bytes_ += s.translations.release_below(span.lo[kTranslations]);
    if (span.lo[kChildRefs] != SIZE_MAX)
        released_bytes_ += s.child_refs.release_below(span.lo[kChildRefs], root_children);
    if (span.lo[kTranslatedShapes] != SIZE_MAX)
        released_bytes_ += s.translated_shapes.release_below(span.lo[kTranslatedShapes]);
}

void Flattener::give_back_released() {
    if (released_bytes_ > 0) malloc_trim(0);
}

}  // namespace vr::flatten_detail
