#include "render/wide_bvh.h"

#include <algorithm>
#include <cmath>

#include "core/huge_pages.h"

namespace vr {
namespace {

double half_area(const BvhNode& n) {
    const double dx = double(n.hi[0]) - n.lo[0], dy = double(n.hi[1]) - n.lo[1],
                 dz = double(n.hi[2]) - n.lo[2];
    return dx * dy + dy * dz + dz * dx;
}

// A node over the n binary nodes `kids` (leaves keep their primitive range; interior children's
// indices are set by the caller); unused lanes get the empty box.
WideBvhNode make_node(const BvhNode* const* kids, int n) {
    WideBvhNode node;
    for (int c = 0; c < kBvhWidth; ++c) {
        for (int k = 0; k < 3; ++k) {
            node.lo[k][c] = c < n ? kids[c]->lo[k] : INFINITY;
            node.hi[k][c] = c < n ? kids[c]->hi[k] : -INFINITY;
        }
        node.child[c] = c < n && kids[c]->count > 0 ? kids[c]->offset : 0;
        node.count[c] = c < n ? kids[c]->count : 0;
    }
    node.lanes = uint8_t(n);
    return node;
}

// Fills node `at` of `out` from the binary interior node `b`: its children, with the interior child
// of largest area opened while fewer than kBvhWidth (the usual greedy collapse: big boxes are the
// ones rays meet).
void collapse(const Bvh& binary, const BvhNode& b, uint32_t at, WideBvh& out) {
    const BvhNode* kids[kBvhWidth] = {&binary.nodes[b.offset], &binary.nodes[b.offset + 1]};
    int n = 2;
    while (n < kBvhWidth) {
        int open = -1;
        double best = -1.0;
        for (int i = 0; i < n; ++i)
            if (kids[i]->count == 0 && half_area(*kids[i]) > best) {
                best = half_area(*kids[i]);
                open = i;
            }
        if (open < 0) break;
        const BvhNode* opened = kids[open];
        kids[open] = &binary.nodes[opened->offset];
        kids[n++] = &binary.nodes[opened->offset + 1];
    }
    out.nodes[at] = make_node(kids, n);
    for (int c = 0; c < n; ++c) {
        if (kids[c]->count > 0) continue;
        const uint32_t index = uint32_t(out.nodes.size());
        out.nodes.emplace_back();
        out.nodes[at].child[c] = index;
        collapse(binary, *kids[c], index, out);
    }
}

}  // namespace

WideBvh collapse_bvh(const Bvh& binary) {
    WideBvh out;
    if (binary.empty()) return out;
    // Every wide node takes at least one binary interior node, so half the binary nodes bound the
    // count and the array never moves (a move would fault its pages in twice). The count is L / 3
    // to L / 2 for L leaves (1M random spheres: 159k of at most 300k); the reserved tail that stays
    // untouched is address space only, never memory.
    reserve_huge(out.nodes, binary.nodes.size() / 2 + 4);
    out.nodes.emplace_back();
    const BvhNode& root = binary.nodes[0];
    if (root.count > 0) {  // a single leaf: one lane
        const BvhNode* only = &root;
        out.nodes[0] = make_node(&only, 1);
        return out;
    }
    collapse(binary, root, 0, out);
    return out;
}

int wide_bvh_depth(const WideBvh& bvh) {
    if (bvh.empty()) return 0;
    int deepest = 0;
    std::vector<std::pair<uint32_t, int>> todo = {{0u, 1}};
    while (!todo.empty()) {
        const auto [i, d] = todo.back();
        todo.pop_back();
        deepest = std::max(deepest, d);
        const WideBvhNode& n = bvh.nodes[i];
        for (int c = 0; c < n.lanes; ++c)
            if (n.count[c] == 0) todo.push_back({n.child[c], d + 1});
    }
    return deepest;
}

}  // namespace vr
