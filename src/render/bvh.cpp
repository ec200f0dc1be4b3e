// Binned SAH BVH builder (Wald 2007, "On fast construction of SAH-based bounding volume
// hierarchies").
//
// Build: recursive over ranges of the box array, partitioned in place. One pass over a range bins
// its boxes by centroid (4-wide float vectors via the compiler's vector extensions; the axis of
// widest centroid spread for large ranges, all three axes for small ones); the bins give both
// children's bounds, and the partition pass their centroid bounds, so each level reads its boxes
// twice. Subtrees above kParallelMin boxes are built on separate threads; the result does not
// depend on the thread count.
#include "render/bvh.h"

#include <algorithm>
#include <cstring>
#include <thread>

#include "core/huge_pages.h"

namespace vr {
namespace {

constexpr int kBins = 16;
constexpr int kMaxDepth = 64;  // then median splits: depth <= 64 + 32 < the traversal stack (128)
constexpr uint32_t kParallelMin = 16 * 1024;
constexpr uint32_t kAllAxesBelow = 1024;  // smaller ranges are binned along all three axes

typedef float f4 __attribute__((vector_size(16)));
typedef int32_t i4 __attribute__((vector_size(16)));

inline f4 vmin(f4 a, f4 b) { return a < b ? a : b; }
inline f4 vmax(f4 a, f4 b) { return a > b ? a : b; }

// A box as two 4-wide vectors; lane 3 is kept at 0.
struct Box4 {
    f4 lo = {INFINITY, INFINITY, INFINITY, 0.0f};
    f4 hi = {-INFINITY, -INFINITY, -INFINITY, 0.0f};
    void extend(const Box4& b) {
        lo = vmin(lo, b.lo);
        hi = vmax(hi, b.hi);
    }
    void extend_point(f4 p) {
        lo = vmin(lo, p);
        hi = vmax(hi, p);
    }
    bool empty() const { return lo[0] > hi[0]; }
    // Half the surface area; only ratios matter.
    double half_area() const {
        if (empty()) return 0.0;
        double dx = double(hi[0]) - lo[0], dy = double(hi[1]) - lo[1], dz = double(hi[2]) - lo[2];
        return dx * dy + dy * dz + dz * dx;
    }
};

// The same without default member values, for arrays that are initialised only in part.
struct Box4Raw {
    f4 lo, hi;
    static Box4Raw empty_box() { return {Box4().lo, Box4().hi}; }
    void extend(const Box4& b) {
        lo = vmin(lo, b.lo);
        hi = vmax(hi, b.hi);
    }
    void extend_point(f4 p) {
        lo = vmin(lo, p);
        hi = vmax(hi, p);
    }
    Box4 box() const {
        Box4 b;
        b.lo = lo;
        b.hi = hi;
        return b;
    }
};

inline Box4 load(const BuildBox& b) {
    Box4 out;
    std::memcpy(&out.lo, b.lo, sizeof(f4));  // lanes 0-2 bounds, lane 3 the id or padding
    std::memcpy(&out.hi, b.hi, sizeof(f4));
    // Zero lane 3 bitwise: the id's bits may read as a denormal or NaN float.
    const i4 mask = {-1, -1, -1, 0};
    out.lo = (f4)((i4)out.lo & mask);
    out.hi = (f4)((i4)out.hi & mask);
    return out;
}

// Centroids are kept doubled (lo + hi) to save a multiplication; only order matters.
inline f4 centroid2(const Box4& b) { return b.lo + b.hi; }
inline float centroid2(const BuildBox& b, int axis) { return b.lo[axis] + b.hi[axis]; }

struct Range {
    uint32_t begin, end;
    Box4 box;        // bounds of the boxes
    Box4 centroids;  // bounds of their doubled centroids
};

// Lays nodes out in sibling pairs: an interior node's two children sit side by side at an even
// index, so with the array aligned to 64 bytes one cache line holds both boxes a traversal step
// tests. Pairs follow each other depth first. Parallel subtrees are built into their own arrays
// and appended, with their child offsets shifted.
class Builder {
  public:
    Builder(BuildBoxes& boxes, const BvhBuildOptions& options) : boxes_(boxes), options_(options) {}

    // Builds the subtree over `range`: returns its root and appends the descendants' pairs to
    // `out`.
    BvhNode build(const Range& range, int depth, int spare_threads, BvhNodeArray& out) {
        BvhNode node;
        set_bounds(node, range.box);
        const uint32_t n = range.end - range.begin;
        if (n == 1) return make_leaf(node, range);

        bool degenerate = true;
        for (int k = 0; k < 3; ++k)
            if (range.centroids.hi[k] > range.centroids.lo[k]) degenerate = false;

        Range left, right;
        int axis = -1;
        if (!degenerate && depth < kMaxDepth) {
            double split_cost;
            axis = split_sah(range, left, right, split_cost);
            if (axis >= 0 && n <= uint32_t(options_.max_leaf_size) && double(n) <= split_cost)
                return make_leaf(node, range);
        }
        if (axis < 0) {
            // Coincident centroids (or a very deep tree): a leaf if small, else halve the range.
            if (n <= uint32_t(std::max(options_.max_leaf_size, 1))) return make_leaf(node, range);
            axis = split_median(range, left, right);
        }
        node.axis = uint8_t(axis);
        node.count = 0;

        const uint32_t pair = uint32_t(out.size());
        out.resize(pair + 2);
        node.offset = pair;
        if (spare_threads > 0 && n >= kParallelMin) {
            const int give =
                (spare_threads - 1) / 2 + (spare_threads - 1) % 2;  // for the new thread
            const int keep = spare_threads - 1 - give;
            BvhNodeArray left_nodes, right_nodes;
            BvhNode left_root, right_root;
            std::thread worker([&, give] {
                reserve_huge(left_nodes, 2 * size_t(left.end - left.begin));
                left_root = build(left, depth + 1, give, left_nodes);
            });
            reserve_huge(right_nodes, 2 * size_t(right.end - right.begin));
            right_root = build(right, depth + 1, keep, right_nodes);
            worker.join();
            out[pair] = append(out, left_nodes, left_root);
            out[pair + 1] = append(out, right_nodes, right_root);
        } else {
            // `out` may grow while a child is built: write the slot afterwards.
            const BvhNode l = build(left, depth + 1, 0, out);
            out[pair] = l;
            const BvhNode r = build(right, depth + 1, 0, out);
            out[pair + 1] = r;
        }
        return node;
    }

    Range root() const {
        Range r{0, uint32_t(boxes_.size()), Box4(), Box4()};
        for (const BuildBox& b : boxes_) {
            Box4 x = load(b);
            r.box.extend(x);
            r.centroids.extend_point(centroid2(x));
        }
        return r;
    }

  private:
    static void set_bounds(BvhNode& node, const Box4& box) {
        for (int k = 0; k < 3; ++k) {
            node.lo[k] = box.lo[k];
            node.hi[k] = box.hi[k];
        }
        node.axis = 0;
        node.unused = 0;
    }

    static BvhNode make_leaf(BvhNode& node, const Range& range) {
        node.offset = range.begin;
        node.count = uint16_t(range.end - range.begin);
        return node;
    }

    // Appends a subtree built on its own (`sub` holds the descendants of `root`) and returns its
    // root with child offsets shifted to the new place; pairs stay at even indices.
    static BvhNode append(BvhNodeArray& out, const BvhNodeArray& sub, BvhNode root) {
        const uint32_t base = uint32_t(out.size());
        out.insert(out.end(), sub.begin(), sub.end());
        for (size_t i = base; i < out.size(); ++i)
            if (out[i].count == 0) out[i].offset += base;
        if (root.count == 0) root.offset += base;
        return root;
    }

    // Binned SAH. Large ranges are binned along the axis where the centroids spread most (as in
    // Wald's builder), small ones along all three. Returns the chosen axis (or -1 when no split
    // separates the boxes), partitions the range and describes both halves; `cost` is in primitive
    // tests.
    int split_sah(const Range& range, Range& left, Range& right, double& cost) {
        struct Bin {  // trivial, so only the nb bins in use get initialised
            Box4Raw box;
            uint32_t count;
        };
        const uint32_t n = range.end - range.begin;
        // Small ranges get fewer bins: setting up and sweeping the bins then costs no more than
        // binning the boxes (there are as many small nodes as boxes).
        const int nb = int(std::min<uint32_t>(kBins, std::max<uint32_t>(n, 2)));
        int axis_first = 0, axis_last = 2;
        if (n >= kAllAxesBelow) {
            int k = 0;
            for (int j = 1; j < 3; ++j)
                if (range.centroids.hi[j] - range.centroids.lo[j] >
                    range.centroids.hi[k] - range.centroids.lo[k])
                    k = j;
            axis_first = axis_last = k;
        }
        Bin bins[3][kBins];
        for (int k = axis_first; k <= axis_last; ++k) {
            for (int i = 0; i < nb; ++i) {
                bins[k][i].box = Box4Raw::empty_box();
                bins[k][i].count = 0;
            }
        }
        const f4 c_lo = range.centroids.lo;
        f4 scale = {0.0f, 0.0f, 0.0f, 0.0f};
        for (int k = axis_first; k <= axis_last; ++k) {
            float extent = range.centroids.hi[k] - range.centroids.lo[k];
            scale[k] = extent > 0.0f ? float(nb) * (1.0f - 1e-6f) / extent : 0.0f;
        }
        const i4 zero = {0, 0, 0, 0}, last = {nb - 1, nb - 1, nb - 1, nb - 1};
        for (uint32_t i = range.begin; i < range.end; ++i) {
            const Box4 b = load(boxes_[i]);
            i4 bin = __builtin_convertvector((centroid2(b) - c_lo) * scale, i4);
            bin = bin < zero ? zero : bin;
            bin = bin > last ? last : bin;
            for (int k = axis_first; k <= axis_last; ++k) {
                Bin& x = bins[k][bin[k]];
                x.count++;
                x.box.extend(b);
            }
        }
        const double parent_area = range.box.half_area();
        int best_axis = -1, best_split = 0;
        double best = INFINITY;
        for (int k = axis_first; k <= axis_last; ++k) {
            if (scale[k] == 0.0f) continue;
            double right_area[kBins];
            uint32_t right_count[kBins];
            Box4 acc;
            uint32_t cnt = 0;
            for (int i = nb - 1; i > 0; --i) {
                acc.extend(bins[k][i].box.box());
                cnt += bins[k][i].count;
                right_area[i] = acc.half_area();
                right_count[i] = cnt;
            }
            acc = Box4();
            cnt = 0;
            for (int i = 0; i < nb - 1; ++i) {
                acc.extend(bins[k][i].box.box());
                cnt += bins[k][i].count;
                const uint32_t rc = right_count[i + 1];
                if (cnt == 0 || rc == 0) continue;
                const double c = cnt * acc.half_area() + rc * right_area[i + 1];
                if (c < best) {
                    best = c;
                    best_axis = k;
                    best_split = i + 1;
                }
            }
        }
        if (best_axis < 0) return -1;
        cost = options_.traversal_cost + (parent_area > 0.0 ? best / parent_area : double(n));
        const int k = best_axis;
        const float lo_k = c_lo[k], scale_k = scale[k];
        auto goes_left = [&](const BuildBox& b) {
            int bin = int((centroid2(b, k) - lo_k) * scale_k);
            return std::clamp(bin, 0, nb - 1) < best_split;
        };
        // Partition in place, collecting both sides' centroid bounds on the way.
        left = {range.begin, 0, Box4(), Box4()};
        right = {0, range.end, Box4(), Box4()};
        uint32_t i = range.begin, j = range.end;
        for (;;) {
            while (i < j && goes_left(boxes_[i]))
                left.centroids.extend_point(centroid2(load(boxes_[i++])));
            while (i < j && !goes_left(boxes_[j - 1]))
                right.centroids.extend_point(centroid2(load(boxes_[--j])));
            if (i >= j) break;
            std::swap(boxes_[i], boxes_[j - 1]);
        }
        left.end = right.begin = i;
        for (int b = 0; b < nb; ++b)
            (b < best_split ? left : right).box.extend(bins[k][b].box.box());
        return k;
    }

    int split_median(const Range& range, Range& left, Range& right) {
        int k = 0;
        for (int j = 1; j < 3; ++j)
            if (range.centroids.hi[j] - range.centroids.lo[j] >
                range.centroids.hi[k] - range.centroids.lo[k])
                k = j;
        const uint32_t mid = range.begin + (range.end - range.begin) / 2;
        std::nth_element(boxes_.begin() + range.begin, boxes_.begin() + mid,
                         boxes_.begin() + range.end, [k](const BuildBox& a, const BuildBox& b) {
                             float ca = centroid2(a, k), cb = centroid2(b, k);
                             return ca < cb || (ca == cb && a.id < b.id);
                         });
        left = {range.begin, mid, Box4(), Box4()};
        right = {mid, range.end, Box4(), Box4()};
        for (Range* side : {&left, &right}) {
            for (uint32_t i = side->begin; i < side->end; ++i) {
                Box4 b = load(boxes_[i]);
                side->box.extend(b);
                side->centroids.extend_point(centroid2(b));
            }
        }
        return k;
    }

    BuildBoxes& boxes_;
    const BvhBuildOptions& options_;
};

}  // namespace

Bvh build_bvh(BuildBoxes boxes, const BvhBuildOptions& options) {
    Bvh bvh;
    if (boxes.empty()) return bvh;
    Builder builder(boxes, options);
    const int spare = std::max(options.threads, 1) - 1;
    reserve_huge(bvh.nodes, 2 * boxes.size() + 2);
    // Slot 0 is the root, slot 1 padding, so that the pairs start at index 2.
    bvh.nodes.resize(2);
    bvh.nodes[0] = builder.build(builder.root(), 0, spare, bvh.nodes);
    bvh.nodes[1] = BvhNode{};
    resize_huge(bvh.order, boxes.size());
    for (size_t i = 0; i < boxes.size(); ++i) bvh.order[i] = boxes[i].id;
    return bvh;
}

}  // namespace vr
