// Binned SAH BVH builder (Wald 2007, "On fast construction of SAH-based bounding volume
// hierarchies").
//
// Build: recursive over ranges of the box array, partitioned in place. One pass over a range bins
// its boxes by centroid (4-wide float vectors via the compiler's vector extensions; the axis of
// widest centroid spread for large ranges, all three axes for small ones); the bins give both
// children's bounds, and the partition pass their centroid bounds, so each level reads its boxes
// twice. Subtrees of kParallelMin boxes or more are tasks that any thread may build (Builder); the
// result does not depend on the thread count.
//
// The Morton build (BvhBuildOptions::morton; Lauterbach et al. 2009, "Fast BVH construction on
// GPUs", as an LBVH) uses the same tasks and layout: the boxes' order is that of their centroids'
// Morton codes, sorted once; a range splits where its highest differing code bit changes, found by
// binary search, and interior bounds are filled in bottom-up after the build.
#include "render/bvh.h"

#include <algorithm>
#include <array>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>

#include "core/huge_pages.h"
#include "core/parallel.h"

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
    int bit = -1;    // Morton build: the highest code bit not shared by the whole range
};

// A subtree built by one thread into its own array. Its root goes into slot `slot` of the parent
// task's array, and its nodes where the serial build would have appended them: at `position` of
// the parent's array, right after the left sibling's subtree.
struct Task {
    Range range;
    int depth = 0;
    Task* parent = nullptr;
    uint32_t slot = 0, position = 0;
    BvhNodeArray nodes;
    BvhNode root{};
    std::vector<Task*> children;  // in the order of their positions
    size_t joined = 0;            // nodes with those of all descendant tasks
    size_t base = 0;              // where nodes[0] lands in the joined array

    // Index in the joined array of nodes[i].
    size_t place(uint32_t i) const {
        size_t at = base + i;
        for (const Task* c : children) {
            if (c->position > i) break;
            at += c->joined;
        }
        return at;
    }
};

// Lays nodes out in sibling pairs: an interior node's two children sit side by side at an even
// index, so with the array aligned to 64 bytes one cache line holds both boxes a traversal step
// tests. Pairs follow each other depth first.
//
// With several threads, a range of at least kParallelMin boxes keeps its left child on the thread
// that split it and queues the right one as a task; an idle thread takes the largest queued task,
// so an uneven split near the root leaves no thread waiting. join() lays the tasks' arrays out as
// the serial build would have: the result depends neither on the thread count nor on timing.
class Builder {
  public:
    Builder(BuildBoxes& boxes, const BvhBuildOptions& options)
        : boxes_(boxes), options_(options), parallel_(options.threads > 1) {}

    // The whole tree over the boxes, into `nodes`: slot 0 the root, slot 1 padding, so that the
    // pairs start at index 2.
    void build_all(BvhNodeArray& nodes, NoFillVector<uint32_t>& order) {
        const int threads = std::max(options_.threads, 1);
        Task& top = tasks_.emplace_back();
        top.range = root(threads);
        if (options_.morton) sort_by_morton(top.range, threads);
        reserve_huge(top.nodes, 2 * boxes_.size() + 2);
        top.nodes.resize(2);
        pending_.push_back(&top);
        std::vector<std::thread> helpers;
        for (int t = 1; t < threads; ++t) helpers.emplace_back([this] { work(); });
        work();
        for (std::thread& t : helpers) t.join();
        // The boxes and the Morton keys are read last by leaf_order: freed before the tasks' nodes
        // are joined into one array, so that they are never held beside both (on a large molecule
        // 40 bytes a primitive, more than the nodes).
        leaf_order(order);
        NoFillVector<uint32_t>().swap(codes_);
        NoFillVector<uint32_t>().swap(index_);
        BuildBoxes().swap(boxes_);
        join(threads, nodes);
        nodes[1] = BvhNode{};
        if (options_.morton) bound_interior_nodes(nodes);
    }

  private:
    // Caller ids in leaf order.
    void leaf_order(NoFillVector<uint32_t>& order) const {
        resize_huge(order, boxes_.size());
        for (size_t i = 0; i < boxes_.size(); ++i) order[i] = box_at(i).id;
    }

    // Builds the subtree over `range` as part of task `self`: returns its root and appends the
    // descendants' pairs to `out` (self's array).
    BvhNode build(const Range& range, int depth, Task& self, BvhNodeArray& out) {
        if (options_.morton) return build_morton(range, depth, self, out);
        BvhNode node;
        set_bounds(node, range.box);
        const uint32_t n = range.end - range.begin;
        if (n == 1) return make_leaf(node, range);
        // A leaf of this size is allowed and no split can cost less: a split costs the traversal
        // and more (split_sah's cost). The tree is the one the SAH makes (the leaf lists its boxes
        // in input order, not split_sah's partition order), without binning the most numerous
        // ranges, which makes the build of a large molecule cheaper (bench/bvh_build.cpp;
        // bench/README.md, "Figures behind the comments").
        if (n <= uint32_t(options_.max_leaf_size) && range_cost(range) <= options_.traversal_cost)
            return make_leaf(node, range);

        bool degenerate = true;
        for (int k = 0; k < 3; ++k)
            if (range.centroids.hi[k] > range.centroids.lo[k]) degenerate = false;

        Range left, right;
        int axis = -1;
        if (!degenerate && depth < kMaxDepth) {
            double split_cost;
            axis = split_sah(range, left, right, split_cost);
            if (axis >= 0 && n <= uint32_t(options_.max_leaf_size) &&
                range_cost(range) <= split_cost)
                return make_leaf(node, range);
        }
        if (axis < 0) {
            // Coincident centroids (or a very deep tree): a leaf if small, else halve the range.
            if (n <= uint32_t(std::max(options_.max_leaf_size, 1))) return make_leaf(node, range);
            axis = split_median(range, left, right);
        }
        node.axis = uint8_t(axis);
        node.count = 0;
        return add_children(node, left, right, depth, self, out);
    }

    // The children's pair of interior node `node`, built (or queued) and written to `out`.
    BvhNode add_children(BvhNode node, const Range& left, const Range& right, int depth, Task& self,
                         BvhNodeArray& out) {
        const uint32_t n = right.end - left.begin;
        const uint32_t pair = uint32_t(out.size());
        out.resize(pair + 2);
        node.offset = pair;
        // `out` may grow while a child is built: write the slots afterwards.
        if (parallel_ && n >= kParallelMin) {
            out[pair + 1] = BvhNode{};  // the child task's root, once join() knows its place
            Task* child = queue(right, depth + 1, &self, pair + 1);
            const BvhNode l = build(left, depth + 1, self, out);
            out[pair] = l;
            child->position = uint32_t(out.size());
            self.children.push_back(child);  // only self's thread touches self.children
        } else {
            const BvhNode l = build(left, depth + 1, self, out);
            out[pair] = l;
            const BvhNode r = build(right, depth + 1, self, out);
            out[pair + 1] = r;
        }
        return node;
    }

    // The Morton build (BvhBuildOptions::morton): the range, ordered by the codes of its
    // centroids, splits where its highest differing code bit changes (a spatial median), or in
    // the middle where all codes are equal; up to max_leaf_size boxes make a leaf. Interior bounds
    // are filled in after the build (bound_interior_nodes), leaves' here.
    BvhNode build_morton(const Range& range, int depth, Task& self, BvhNodeArray& out) {
        BvhNode node;
        const uint32_t n = range.end - range.begin;
        if (n <= uint32_t(std::max(options_.max_leaf_size, 1))) {
            Box4 box;
            for (uint32_t i = range.begin; i < range.end; ++i) box.extend(load(box_at(i)));
            set_bounds(node, box);
            return make_leaf(node, range);
        }
        int bit = range.bit;
        uint32_t mid = range.begin + n / 2;
        for (; bit >= 0; --bit) {
            // Every code of the range agrees above `bit`: those with it set come last.
            const uint32_t mask = uint32_t(1) << bit;
            const auto split =
                std::partition_point(codes_.begin() + range.begin, codes_.begin() + range.end,
                                     [mask](uint32_t code) { return (code & mask) == 0; });
            const auto at = uint32_t(split - codes_.begin());
            if (at != range.begin && at != range.end) {
                mid = at;
                break;
            }
        }
        set_bounds(node, Box4());
        node.axis = uint8_t(bit >= 0 ? 2 - bit % 3 : 0);
        node.count = 0;
        Range left{range.begin, mid, Box4(), Box4(), bit - 1};
        Range right{mid, range.end, Box4(), Box4(), bit - 1};
        if (bit < 0) left.bit = right.bit = -1;
        return add_children(node, left, right, depth, self, out);
    }

    // 10 bits an axis, interleaved: bit 3l + 2 is x's bit l, 3l + 1 y's, 3l z's.
    static uint32_t spread_bits(uint32_t v) {
        v &= 0x3ffu;
        v = (v | (v << 16)) & 0x030000ffu;
        v = (v | (v << 8)) & 0x0300f00fu;
        v = (v | (v << 4)) & 0x030c30c3u;
        v = (v | (v << 2)) & 0x09249249u;
        return v;
    }

    // keys_: (Morton code of the centroid << 32 | box index), sorted by code and then index (a
    // stable radix sort of the code's four bytes), so the order depends on the boxes alone.
    void sort_by_morton(Range& top, int threads) {
        const size_t n = boxes_.size();
        const f4 lo = top.centroids.lo;
        f4 scale = {0.0f, 0.0f, 0.0f, 0.0f};
        for (int k = 0; k < 3; ++k) {
            const float extent = top.centroids.hi[k] - top.centroids.lo[k];
            scale[k] = extent > 0.0f ? 1024.0f * (1.0f - 1e-6f) / extent : 0.0f;
        }
        resize_huge(keys_, n);
        const bool remake =
            n >= options_.boxes_in_code_order_from && options_.remake_box != nullptr;
        const int chunks = chunks_for(n, threads);
        parallel_ranges(n, chunks, [&](size_t begin, size_t end, int) {
            const i4 zero = {0, 0, 0, 0}, last = {1023, 1023, 1023, 1023};
            for (size_t i = begin; i < end; ++i) {
                i4 q = __builtin_convertvector((centroid2(load(boxes_[i])) - lo) * scale, i4);
                q = q < zero ? zero : q;
                q = q > last ? last : q;
                const uint32_t code = (spread_bits(uint32_t(q[0])) << 2) |
                                      (spread_bits(uint32_t(q[1])) << 1) |
                                      spread_bits(uint32_t(q[2]));
                // The id when the boxes are remade from it in code order (the sort moves only
                // code bytes and is stable, so the order is the same).
                keys_[i] = (uint64_t(code) << 32) | (remake ? boxes_[i].id : uint32_t(i));
            }
        });
        NoFillVector<uint64_t> other;
        resize_huge(other, n);
        std::vector<std::array<size_t, 256>> start(static_cast<size_t>(chunks));
        for (int shift = 32; shift < 64; shift += 8) {
            parallel_ranges(n, chunks, [&](size_t begin, size_t end, int c) {
                std::array<size_t, 256>& count = start[size_t(c)];
                count.fill(0);
                for (size_t i = begin; i < end; ++i) ++count[(keys_[i] >> shift) & 0xff];
            });
            size_t at = 0;  // digit by digit, chunk by chunk: the sort is stable
            for (int d = 0; d < 256; ++d)
                for (auto& count : start) {
                    const size_t c = count[size_t(d)];
                    count[size_t(d)] = at;
                    at += c;
                }
            parallel_ranges(n, chunks, [&](size_t begin, size_t end, int c) {
                std::array<size_t, 256>& next = start[size_t(c)];
                for (size_t i = begin; i < end; ++i)
                    other[next[(keys_[i] >> shift) & 0xff]++] = keys_[i];
            });
            keys_.swap(other);
        }
        NoFillVector<uint64_t>().swap(other);
        if (remake)
            remake_boxes_in_code_order(threads);
        else
            split_keys(threads);
        top.bit = 29;
    }

    // The box at code order position i.
    const BuildBox& box_at(size_t i) const { return boxes_[index_.empty() ? i : index_[i]]; }

    // The sorted keys as their codes and box indices.
    void split_keys(int threads) {
        const size_t n = keys_.size();
        resize_huge(codes_, n);
        resize_huge(index_, n);
        parallel_ranges(n, chunks_for(n, threads), [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i) {
                codes_[i] = uint32_t(keys_[i] >> 32);
                index_[i] = uint32_t(keys_[i]);
            }
        });
        NoFillVector<uint64_t>().swap(keys_);
    }

    // The boxes in code order made again from their ids (keys_ holds ids, not indices): box i then
    // is the i-th in code order, so no index (4 bytes a box) is held beside the tasks' nodes at the
    // build's peak. Each box is written once from the caller's primitives, on every thread
    // (moving them along the permutation's cycles instead waited on a cache miss a box, on one).
    void remake_boxes_in_code_order(int threads) {
        const size_t n = keys_.size();
        resize_huge(codes_, n);
        parallel_ranges(n, chunks_for(n, threads), [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i) {
                options_.remake_box(uint32_t(keys_[i]), boxes_[i]);
                codes_[i] = uint32_t(keys_[i] >> 32);
            }
        });
        NoFillVector<uint64_t>().swap(keys_);
    }

    // Interior bounds from the children's, last node first: a pair always follows its parent.
    static void bound_interior_nodes(BvhNodeArray& nodes) {
        for (size_t i = nodes.size(); i-- > 0;) {
            BvhNode& node = nodes[i];
            if (i == 1 || node.count > 0) continue;
            for (int k = 0; k < 3; ++k) {
                node.lo[k] = std::min(nodes[node.offset].lo[k], nodes[node.offset + 1].lo[k]);
                node.hi[k] = std::max(nodes[node.offset].hi[k], nodes[node.offset + 1].hi[k]);
            }
        }
    }

    Range root(int threads) const {
        const size_t n = boxes_.size();
        const int chunks = chunks_for(n, threads);
        std::vector<Range> parts(size_t(chunks), Range{0, uint32_t(n), Box4(), Box4()});
        parallel_ranges(n, chunks, [&](size_t begin, size_t end, int c) {
            Range& r = parts[size_t(c)];
            for (size_t i = begin; i < end; ++i) {
                const Box4 x = load(boxes_[i]);
                r.box.extend(x);
                r.centroids.extend_point(centroid2(x));
            }
        });
        // min and max are exact: the bounds do not depend on the chunks.
        for (size_t c = 1; c < parts.size(); ++c) {
            parts[0].box.extend(parts[c].box);
            parts[0].centroids.extend(parts[c].centroids);
        }
        return parts[0];
    }

    Task* queue(const Range& range, int depth, Task* parent, uint32_t slot) {
        std::lock_guard<std::mutex> lock(mutex_);
        Task& t = tasks_.emplace_back();  // a deque: the other tasks stay where they are
        t.range = range;
        t.depth = depth;
        t.parent = parent;
        t.slot = slot;
        pending_.push_back(&t);
        wake_.notify_one();
        return &t;
    }

    // Runs queued tasks, the largest first, until none is queued or running.
    void work() {
        std::unique_lock<std::mutex> lock(mutex_);
        for (;;) {
            wake_.wait(lock, [&] { return !pending_.empty() || busy_ == 0; });
            if (pending_.empty()) return;
            const auto largest =
                std::max_element(pending_.begin(), pending_.end(), [](Task* a, Task* b) {
                    return a->range.end - a->range.begin < b->range.end - b->range.begin;
                });
            Task* t = *largest;
            pending_.erase(largest);
            ++busy_;
            lock.unlock();
            // (Not on huge pages: a queued task's array is reserved for its worst case and filled
            // to about a third of it, and the 2 MiB page its nodes end in would be held whole:
            // 58 MiB of hundreds of tasks at the peak of a 10M-atom build, bench/README.md "Issue
            // 45: the atom's record". The top task's array stays on them.)
            if (t->nodes.capacity() == 0)
                t->nodes.reserve(2 * size_t(t->range.end - t->range.begin));
            t->root = build(t->range, t->depth, *t, t->nodes);
            lock.lock();
            if (--busy_ == 0 && pending_.empty()) wake_.notify_all();
        }
    }

    // The tasks' arrays as one, in the serial build's order, with the offsets of interior nodes
    // moved to their children's places.
    void join(int threads, BvhNodeArray& nodes) {
        Task& top = tasks_.front();
        if (tasks_.size() == 1) {
            nodes = std::move(top.nodes);
            nodes[0] = top.root;
            return;
        }
        // A child task is created after its parent: sizes backwards, places forwards.
        for (auto t = tasks_.rbegin(); t != tasks_.rend(); ++t) {
            t->joined = t->nodes.size();
            for (const Task* c : t->children) t->joined += c->joined;
        }
        for (Task& t : tasks_) {
            size_t before = 0;
            for (Task* c : t.children) {
                c->base = t.base + c->position + before;
                before += c->joined;
            }
        }
        auto moved = [](const Task& t, BvhNode node) {
            if (node.count == 0) node.offset = uint32_t(t.place(node.offset));
            return node;
        };
        reserve_huge(nodes, top.joined);
        nodes.resize(top.joined);
        // Each task's array is freed once copied (place() reads its children, not its nodes):
        // the joined array and the tasks' are not held whole together.
        parallel_ranges(tasks_.size(), threads, [&](size_t begin, size_t end, int) {
            for (size_t k = begin; k < end; ++k) {
                Task& t = tasks_[k];
                for (uint32_t i = 0; i < t.nodes.size(); ++i)
                    nodes[t.place(i)] = moved(t, t.nodes[i]);
                BvhNodeArray().swap(t.nodes);
            }
        });
        // The slots that waited for a child task's root.
        for (const Task& t : tasks_)
            if (t.parent != nullptr) nodes[t.parent->place(t.slot)] = moved(t, t.root);
        nodes[0] = moved(top, top.root);
    }

    static void set_bounds(BvhNode& node, const Box4& box) {
        for (int k = 0; k < 3; ++k) {
            node.lo[k] = box.lo[k];
            node.hi[k] = box.hi[k];
        }
        node.axis = 0;
        node.unused = 0;
    }

    // What testing every primitive of `range` costs, in sphere tests.
    double range_cost(const Range& range) const {
        double c = 0.0;
        for (uint32_t i = range.begin; i < range.end; ++i) c += boxes_[i].cost;
        return c;
    }

    static BvhNode make_leaf(BvhNode& node, const Range& range) {
        node.offset = range.begin;
        node.count = uint16_t(range.end - range.begin);
        return node;
    }

    // Binned SAH. Large ranges are binned along the axis where the centroids spread most (as in
    // Wald's builder), small ones along all three. Returns the chosen axis (or -1 when no split
    // separates the boxes), partitions the range and describes both halves; `cost` is in sphere
    // tests (BuildBox::cost).
    int split_sah(const Range& range, Range& left, Range& right, double& cost) {
        struct Bin {  // trivial, so only the nb bins in use get initialised
            Box4Raw box;
            uint32_t count;
            double cost;  // of the primitives, in sphere tests
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
                bins[k][i].cost = 0.0;
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
            const double box_cost = boxes_[i].cost;
            i4 bin = __builtin_convertvector((centroid2(b) - c_lo) * scale, i4);
            bin = bin < zero ? zero : bin;
            bin = bin > last ? last : bin;
            for (int k = axis_first; k <= axis_last; ++k) {
                Bin& x = bins[k][bin[k]];
                x.count++;
                x.cost += box_cost;
                x.box.extend(b);
            }
        }
        const double parent_area = range.box.half_area();
        int best_axis = -1, best_split = 0;
        double best = INFINITY;
        for (int k = axis_first; k <= axis_last; ++k) {
            if (scale[k] == 0.0f) continue;
            double right_area[kBins], right_cost[kBins];
            uint32_t right_count[kBins];
            Box4 acc;
            uint32_t cnt = 0;
            double cost_sum = 0.0;
            for (int i = nb - 1; i > 0; --i) {
                acc.extend(bins[k][i].box.box());
                cnt += bins[k][i].count;
                cost_sum += bins[k][i].cost;
                right_area[i] = acc.half_area();
                right_count[i] = cnt;
                right_cost[i] = cost_sum;
            }
            acc = Box4();
            cnt = 0;
            cost_sum = 0.0;
            for (int i = 0; i < nb - 1; ++i) {
                acc.extend(bins[k][i].box.box());
                cnt += bins[k][i].count;
                cost_sum += bins[k][i].cost;
                if (cnt == 0 || right_count[i + 1] == 0) continue;
                const double c = cost_sum * acc.half_area() + right_cost[i + 1] * right_area[i + 1];
                if (c < best) {
                    best = c;
                    best_axis = k;
                    best_split = i + 1;
                }
            }
        }
        if (best_axis < 0) return -1;
        cost =
            options_.traversal_cost + (parent_area > 0.0 ? best / parent_area : range_cost(range));
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
    NoFillVector<uint64_t> keys_;   // the Morton build's order while it sorts (sort_by_morton)
    NoFillVector<uint32_t> codes_;  // then the Morton codes of the boxes, in their order
    NoFillVector<uint32_t> index_;  // and the box of each, unless the boxes were moved (box_at)
    const BvhBuildOptions& options_;
    const bool parallel_;
    std::deque<Task> tasks_;
    std::vector<Task*> pending_;
    std::mutex mutex_;  // guards tasks_ (growing), pending_ and busy_
    std::condition_variable wake_;
    int busy_ = 0;  // tasks running
};

}  // namespace

Bvh build_bvh(BuildBoxes boxes, const BvhBuildOptions& options) {
    Bvh bvh;
    if (boxes.empty()) return bvh;
    Builder builder(boxes, options);
    builder.build_all(bvh.nodes, bvh.order);
    return bvh;
}

}  // namespace vr
