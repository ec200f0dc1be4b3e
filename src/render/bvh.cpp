// Binned SAH BVH builder (Wald 2007, "On fast construction of SAH-based bounding volume hierarchies").
//
// Build: recursive over ranges of the box array, partitioned in place; nodes are first written to a
// temporary array (allocated with an atomic counter, so parallel subtrees need no locks) and then
// laid out depth first, which makes the result independent of thread timing.
#include "render/bvh.h"

#include <algorithm>
#include <atomic>
#include <thread>

namespace vr {
namespace {

constexpr int kBins = 16;
constexpr double kTraversalCost = 1.0;  // relative to one primitive test
constexpr int kMaxDepth = 96;           // beyond this, split at the median: bounds the traversal stack
constexpr size_t kParallelMin = 32 * 1024;

struct Box {
    float lo[3] = {INFINITY, INFINITY, INFINITY};
    float hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    void extend(const BuildBox& b) {
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], b.lo[k]);
            hi[k] = std::max(hi[k], b.hi[k]);
        }
    }
    void extend(const Box& b) {
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], b.lo[k]);
            hi[k] = std::max(hi[k], b.hi[k]);
        }
    }
    // Half the surface area; only ratios matter.
    double half_area() const {
        if (lo[0] > hi[0]) return 0.0;
        double dx = double(hi[0]) - lo[0], dy = double(hi[1]) - lo[1], dz = double(hi[2]) - lo[2];
        return dx * dy + dy * dz + dz * dx;
    }
};

struct TempNode {
    Box box;
    uint32_t left = 0, right = 0;  // children (interior)
    uint32_t first = 0, count = 0; // range (leaf: count > 0)
    uint8_t axis = 0;
};

// Centroids are compared doubled (lo + hi) to save a multiplication; only order matters.
inline float centroid2(const BuildBox& b, int axis) { return b.lo[axis] + b.hi[axis]; }

class Builder {
public:
    Builder(std::vector<BuildBox>& boxes, const BvhBuildOptions& options)
        : boxes_(boxes), options_(options), nodes_(boxes.empty() ? 0 : 2 * boxes.size() - 1) {}

    uint32_t build(uint32_t begin, uint32_t end, const Box& box, int depth, int spare_threads) {
        uint32_t index = next_node_.fetch_add(1, std::memory_order_relaxed);
        TempNode& node = nodes_[index];
        node.box = box;
        uint32_t n = end - begin;

        Box centroids;
        for (uint32_t i = begin; i < end; ++i) {
            for (int k = 0; k < 3; ++k) {
                float c = centroid2(boxes_[i], k);
                centroids.lo[k] = std::min(centroids.lo[k], c);
                centroids.hi[k] = std::max(centroids.hi[k], c);
            }
        }

        uint32_t mid = 0;
        Box left_box, right_box;
        int axis = -1;
        if (n == 1) {
            make_leaf(node, begin, n);
            return index;
        }
        bool degenerate = true;
        for (int k = 0; k < 3; ++k)
            if (centroids.hi[k] > centroids.lo[k]) degenerate = false;

        if (!degenerate && depth < kMaxDepth) {
            double split_cost;
            axis = find_split(begin, end, box, centroids, mid, left_box, right_box, split_cost);
            if (axis >= 0 && n <= uint32_t(options_.max_leaf_size) && double(n) <= split_cost) {
                make_leaf(node, begin, n);
                return index;
            }
        }
        if (axis < 0) {
            // Coincident centroids (or a very deep tree): a leaf if small, else halve the range.
            if (n <= uint32_t(std::max(options_.max_leaf_size, 1))) {
                make_leaf(node, begin, n);
                return index;
            }
            int k = 0;
            for (int j = 1; j < 3; ++j)
                if (centroids.hi[j] - centroids.lo[j] > centroids.hi[k] - centroids.lo[k]) k = j;
            mid = begin + n / 2;
            std::nth_element(boxes_.begin() + begin, boxes_.begin() + mid, boxes_.begin() + end,
                             [k](const BuildBox& a, const BuildBox& b) {
                                 float ca = centroid2(a, k), cb = centroid2(b, k);
                                 return ca < cb || (ca == cb && a.id < b.id);
                             });
            axis = k;
            left_box = Box();
            right_box = Box();
            for (uint32_t i = begin; i < mid; ++i) left_box.extend(boxes_[i]);
            for (uint32_t i = mid; i < end; ++i) right_box.extend(boxes_[i]);
        }

        node.axis = uint8_t(axis);
        if (spare_threads > 0 && n >= kParallelMin) {
            int give = spare_threads / 2 + spare_threads % 2 - 1;  // threads left for the new thread
            int keep = spare_threads - 1 - give;
            uint32_t left = 0;
            std::thread worker([&, begin, mid, depth, give] {
                left = build(begin, mid, left_box, depth + 1, give);
            });
            uint32_t right = build(mid, end, right_box, depth + 1, keep);
            worker.join();
            nodes_[index].left = left;
            nodes_[index].right = right;
        } else {
            uint32_t left = build(begin, mid, left_box, depth + 1, 0);
            uint32_t right = build(mid, end, right_box, depth + 1, 0);
            nodes_[index].left = left;
            nodes_[index].right = right;
        }
        return index;
    }

    // Depth-first layout: the first child directly follows its parent.
    void flatten(uint32_t temp, std::vector<BvhNode>& out) {
        const TempNode& t = nodes_[temp];
        uint32_t at = uint32_t(out.size());
        out.emplace_back();
        BvhNode& n = out[at];
        for (int k = 0; k < 3; ++k) {
            n.lo[k] = t.box.lo[k];
            n.hi[k] = t.box.hi[k];
        }
        n.unused = 0;
        if (t.count > 0) {
            n.offset = t.first;
            n.count = uint16_t(t.count);
            n.axis = 0;
            return;
        }
        n.count = 0;
        n.axis = t.axis;
        flatten(t.left, out);
        uint32_t second = uint32_t(out.size());
        out[at].offset = second;
        flatten(t.right, out);
    }

    uint32_t node_count() const { return next_node_.load(); }

private:
    static void make_leaf(TempNode& node, uint32_t begin, uint32_t n) {
        node.first = begin;
        node.count = n;
    }

    // Binned SAH over all three axes. Returns the axis (or -1), partitions [begin, end) at `mid` and
    // gives the children's bounds and the split's cost in units of primitive tests.
    int find_split(uint32_t begin, uint32_t end, const Box& box, const Box& centroids, uint32_t& mid,
                   Box& left_box, Box& right_box, double& cost) {
        struct Bin {
            Box box;
            uint32_t count = 0;
        };
        Bin bins[3][kBins];
        double scale[3];
        for (int k = 0; k < 3; ++k) {
            double extent = double(centroids.hi[k]) - centroids.lo[k];
            scale[k] = extent > 0.0 ? kBins * (1.0 - 1e-6) / extent : 0.0;
        }
        auto bin_of = [&](const BuildBox& b, int k) {
            int i = int((double(centroid2(b, k)) - centroids.lo[k]) * scale[k]);
            return std::clamp(i, 0, kBins - 1);
        };
        for (uint32_t i = begin; i < end; ++i) {
            const BuildBox& b = boxes_[i];
            for (int k = 0; k < 3; ++k) {
                Bin& bin = bins[k][bin_of(b, k)];
                bin.count++;
                bin.box.extend(b);
            }
        }
        double parent_area = box.half_area();
        int best_axis = -1, best_split = 0;
        double best_cost = INFINITY;
        for (int k = 0; k < 3; ++k) {
            if (scale[k] == 0.0) continue;
            // Sweep from the right collecting suffix areas, then from the left.
            double right_area[kBins];
            uint32_t right_count[kBins];
            Box acc;
            uint32_t cnt = 0;
            for (int i = kBins - 1; i > 0; --i) {
                acc.extend(bins[k][i].box);
                cnt += bins[k][i].count;
                right_area[i] = acc.half_area();
                right_count[i] = cnt;
            }
            acc = Box();
            cnt = 0;
            for (int i = 0; i < kBins - 1; ++i) {
                acc.extend(bins[k][i].box);
                cnt += bins[k][i].count;
                uint32_t rc = right_count[i + 1];
                if (cnt == 0 || rc == 0) continue;
                double c = cnt * acc.half_area() + rc * right_area[i + 1];
                if (c < best_cost) {
                    best_cost = c;
                    best_axis = k;
                    best_split = i + 1;
                }
            }
        }
        if (best_axis < 0) return -1;
        cost = kTraversalCost + (parent_area > 0.0 ? best_cost / parent_area : double(end - begin));
        int k = best_axis;
        auto it = std::partition(boxes_.begin() + begin, boxes_.begin() + end,
                                 [&](const BuildBox& b) { return bin_of(b, k) < best_split; });
        mid = uint32_t(it - boxes_.begin());
        left_box = Box();
        right_box = Box();
        for (int i = 0; i < best_split; ++i) left_box.extend(bins[k][i].box);
        for (int i = best_split; i < kBins; ++i) right_box.extend(bins[k][i].box);
        return k;
    }

    std::vector<BuildBox>& boxes_;
    const BvhBuildOptions& options_;
    std::vector<TempNode> nodes_;
    std::atomic<uint32_t> next_node_{0};
};

}  // namespace

Bvh build_bvh(std::vector<BuildBox> boxes, const BvhBuildOptions& options) {
    Bvh bvh;
    if (boxes.empty()) return bvh;
    Builder builder(boxes, options);
    Box root;
    for (const BuildBox& b : boxes) root.extend(b);
    int spare = std::max(options.threads, 1) - 1;
    uint32_t root_index = builder.build(0, uint32_t(boxes.size()), root, 0, spare);
    bvh.nodes.reserve(builder.node_count());
    builder.flatten(root_index, bvh.nodes);
    bvh.order.resize(boxes.size());
    for (size_t i = 0; i < boxes.size(); ++i) bvh.order[i] = boxes[i].id;
    return bvh;
}

}  // namespace vr
