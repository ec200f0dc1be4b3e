// The BVH builder alone: build_bvh over the boxes of spheres read from a text file of "x y z r"
// lines, each repetition timed on its own (no best-of: the median is what to quote), with the
// tree's node count and SAH cost, so that a change to render/bvh.cpp can show both its time and
// whether the tree stayed the same.
//
//   bvh_build SPHERES.txt [--threads N] [--reps N]
//
// A molecule's spheres from tools/gen_molecule.py's file:
//   awk '/translation/ {t=$2" "$3" "$4} /radius/ {print t, $5}' m.wrl > m.txt
// Not built by default: configure with -DVRMLRAY_BENCH=ON and `cmake --build BUILD --target
// bvh_build` (it links the render layer alone).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "render/bvh.h"

namespace {

using namespace vr;

// Half the surface area of a node's box.
double half_area(const BvhNode& n) {
    const double dx = double(n.hi[0]) - n.lo[0], dy = double(n.hi[1]) - n.lo[1],
                 dz = double(n.hi[2]) - n.lo[2];
    return dx * dy + dy * dz + dz * dx;
}

// The SAH cost of the binary tree relative to its root's area: interior nodes at the builder's
// traversal cost, leaves at one test a box.
double sah_cost(const Bvh& bvh, double traversal_cost) {
    double sum = 0.0;
    for (size_t i = 0; i < bvh.nodes.size(); ++i) {
        if (i == 1) continue;  // padding
        const BvhNode& n = bvh.nodes[i];
        sum += half_area(n) * (n.count > 0 ? double(n.count) : traversal_cost);
    }
    return sum / half_area(bvh.nodes[0]);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: bvh_build SPHERES.txt [--threads N] [--reps N]\n");
        return 2;
    }
    int threads = 1, reps = 5;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (std::strcmp(argv[i], "--threads") == 0) threads = std::atoi(argv[i + 1]);
        if (std::strcmp(argv[i], "--reps") == 0) reps = std::atoi(argv[i + 1]);
    }
    FILE* f = std::fopen(argv[1], "r");
    if (f == nullptr) {
        std::fprintf(stderr, "%s: cannot open\n", argv[1]);
        return 1;
    }
    std::vector<double> spheres;  // x y z r
    double v[4];
    while (std::fscanf(f, "%lf %lf %lf %lf", &v[0], &v[1], &v[2], &v[3]) == 4)
        spheres.insert(spheres.end(), v, v + 4);
    std::fclose(f);
    const size_t n = spheres.size() / 4;
    if (n == 0) {
        std::fprintf(stderr, "%s: no spheres\n", argv[1]);
        return 1;
    }
    BvhBuildOptions options;
    options.threads = threads;
    options.traversal_cost = 4.0;  // as Accel builds
    std::vector<double> ms;
    for (int rep = 0; rep < reps; ++rep) {
        BuildBoxes boxes;
        boxes.resize(n);
        for (size_t i = 0; i < n; ++i) {
            const double* s = &spheres[4 * i];
            const Vec3 c(s[0], s[1], s[2]);
            boxes[i] = make_build_box(c - Vec3(s[3]), c + Vec3(s[3]), uint32_t(i));
        }
        const auto start = std::chrono::steady_clock::now();
        const Bvh bvh = build_bvh(std::move(boxes), options);
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
        std::printf("run %d: %.1f ms, %zu nodes, SAH cost %.3f\n", rep + 1, ms.back(),
                    bvh.nodes.size(), sah_cost(bvh, options.traversal_cost));
    }
    std::sort(ms.begin(), ms.end());
    std::printf("%zu spheres, %d thread(s): median %.1f ms of %d runs (%.1f-%.1f)\n", n, threads,
                ms[ms.size() / 2], reps, ms.front(), ms.back());
    return 0;
}
