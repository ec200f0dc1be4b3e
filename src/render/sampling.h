// Pixel samplers (docs/manual.md, Samplers; the seed thesis 000_*, section 6). A sampler decides
// where in a pixel to trace and how often, and how the samples make the pixel's value. All of them
// are a box filter over the pixel except quincunx and adaptive, whose corner taps are shared with
// the neighbouring pixels (their weights: centre 1/2, each corner 1/8, as the seed describes).
//
// Random positions come from a counter-based hash of (seed, pixel, sample index), never from a
// stream shared between pixels, so an image is the same for every thread count and tile order.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/hash.h"
#include "core/math.h"
#include "render/options.h"

namespace vr {

// What one camera ray brings back: colour, and alpha = 1 - the weight with which the background
// reaches it (docs/manual.md, render). Alpha is carried as itself, not as that weight, so that a
// tiny alpha (thin gas: -expm1(-1e-14)) keeps its digits instead of being 1 - (1 - 1e-14).
struct SampleValue {
    Vec3 color{0.0};
    double alpha = 0.0;
};

// The kind named `name`, or nullopt when kSamplerNames lacks it.
std::optional<SamplerKind> sampler_kind(const std::string& name);
// kSamplerNames joined by `separator` ("center, grid, ...").
std::string sampler_names(const std::string& separator = ", ");
// The name --sampler gives `kind`.
inline const char* sampler_name(SamplerKind kind) { return kSamplerNames[size_t(kind)]; }

struct PixelSampler {
    SamplerKind kind = SamplerKind::Center;
    int n = 1;          // grid, jitter: n x n cells; rgss, rooks8: the pattern tiled n x n
    uint64_t seed = 0;  // jitter, statistical
    // adaptive: subdivide where corner and centre differ by more
    double adaptive_threshold = kDefaultAdaptiveThreshold;
    int adaptive_depth = kDefaultAdaptiveDepth;  // adaptive: at most this many subdivisions
    // statistical: stop when the standard error of the mean is below
    double noise_threshold = kDefaultNoiseThreshold;
    int min_samples = 16;  // statistical: samples before the first test, stratified 4 x 4
    int max_samples = kDefaultStatisticalCap;  // statistical: the cap

    // Samples of one pixel for the fixed patterns (center, grid, rgss, rooks8, jitter); 0 for the
    // others, whose count varies (quincunx and adaptive share corners; statistical stops on its
    // own).
    int fixed_samples_per_pixel() const;
    bool shares_corners() const {
        return kind == SamplerKind::Quincunx || kind == SamplerKind::Adaptive;
    }
};

// From options.sampler, options.spp and the sampler thresholds; false and a message when they do
// not fit together (grid and jitter need a square spp, rgss 4 m^2, rooks8 8 m^2; quincunx and
// adaptive take no --spp; statistical reads --spp as its cap).
bool make_sampler(const RenderOptions& options, PixelSampler& sampler, std::string& error);

// Uniform numbers in [0, 1) from (seed, pixel, index): SplitMix64's finaliser over the combined
// key.
inline uint64_t sample_hash(uint64_t seed, int px, int py, uint64_t index) {
    uint64_t z = seed * 0x9E3779B97F4A7C15ull ^ (uint64_t(uint32_t(px)) << 32 | uint32_t(py));
    z += (index + 1) * 0xBF58476D1CE4E5B9ull;
    z = splitmix64_mix(z);
    z = (z ^ (z >> 29)) * 0xBF58476D1CE4E5B9ull;  // second round: neighbouring keys stay unrelated
    return z ^ (z >> 32);
}
inline double sample_uniform(uint64_t seed, int px, int py, uint64_t index) {
    return double(sample_hash(seed, px, py, index) >> 11) * 0x1.0p-53;
}

// Positions, as offsets in [0,1)^2 from the pixel's top-left corner, of the fixed patterns; empty
// for the other kinds. Public for the tests of the patterns.
void fixed_offsets(const PixelSampler& sampler, int px, int py, std::vector<Vec2>& offsets);

// Per-thread work space of the samplers.
struct SamplerScratch {
    std::vector<Vec2> offsets;
    std::vector<SampleValue> corners;  // quincunx, adaptive: the tile's (w+1) x (h+1) corner taps
    std::vector<int> lattice_slot;     // adaptive: lattice point -> index in lattice_values, -1
    std::vector<int> lattice_touched;
    std::vector<SampleValue> lattice_values;
};

namespace sampling_detail {

inline void accumulate(SampleValue& sum, const SampleValue& s, double w) {
    sum.color += w * s.color;
    sum.alpha += w * s.alpha;
}

// The largest difference between two samples over colour and alpha.
inline double difference(const SampleValue& a, const SampleValue& b) {
    return std::max({std::abs(a.color.x - b.color.x), std::abs(a.color.y - b.color.y),
                     std::abs(a.color.z - b.color.z), std::abs(a.alpha - b.alpha)});
}

// Adaptive supersampling inside one pixel. Points live on the lattice of spacing 1/2^(depth+1)
// pixel; `at(i, j)` traces lattice point (i, j) once and remembers it. The square with centre
// (ci, cj) and half-size h (lattice units) has its value as the mean over its four quadrants: a
// quadrant whose corner differs from the centre by more than the threshold is subdivided, else it
// is (corner + centre) / 2 -- so without subdivision the weights are quincunx's.
template <class At>
SampleValue adaptive_square(const PixelSampler& s, At& at, int ci, int cj, int h, int depth) {
    const SampleValue centre = at(ci, cj);
    SampleValue sum;
    for (int q = 0; q < 4; ++q) {
        const int di = (q & 1) ? h : -h, dj = (q & 2) ? h : -h;
        const SampleValue corner = at(ci + di, cj + dj);
        if (depth < s.adaptive_depth && h >= 2 &&
            difference(corner, centre) > s.adaptive_threshold) {
            accumulate(sum, adaptive_square(s, at, ci + di / 2, cj + dj / 2, h / 2, depth + 1),
                       0.25);
        } else {
            accumulate(sum, corner, 0.125);
            accumulate(sum, centre, 0.125);
        }
    }
    return sum;
}

}  // namespace sampling_detail

// Renders the pixels [x0, x1) x [y0, y1) of a tile: eval(x, y) -> SampleValue traces the camera ray
// through image point (x, y) (pixel units, y down); store(px, py, value) receives each pixel's
// value. Corner taps of quincunx and adaptive are traced once per tile and shared by its pixels.
template <class Eval, class Store>
void sample_tile(const PixelSampler& s, int x0, int y0, int x1, int y1, SamplerScratch& scratch,
                 Eval&& eval, Store&& store) {
    using namespace sampling_detail;
    if (s.shares_corners()) {
        const int w = x1 - x0 + 1;
        scratch.corners.resize(size_t(w) * size_t(y1 - y0 + 1));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                scratch.corners[size_t(y - y0) * w + size_t(x - x0)] = eval(x, y);
        const int side = (1 << (s.adaptive_depth + 1)) + 1;  // lattice points across a pixel
        if (s.kind == SamplerKind::Adaptive && scratch.lattice_slot.size() != size_t(side) * side)
            scratch.lattice_slot.assign(size_t(side) * side, -1);
        for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) {
                const SampleValue* c = &scratch.corners[size_t(y - y0) * w + size_t(x - x0)];
                const SampleValue corner[4] = {c[0], c[1], c[w], c[w + 1]};
                if (s.kind == SamplerKind::Quincunx) {
                    SampleValue v = eval(x + 0.5, y + 0.5);
                    v.color *= 0.5;
                    v.alpha *= 0.5;
                    for (const SampleValue& k : corner) accumulate(v, k, 0.125);
                    store(x, y, v);
                    continue;
                }
                const int last = side - 1;
                auto at = [&](int i, int j) -> SampleValue {
                    if ((i == 0 || i == last) && (j == 0 || j == last))
                        return corner[(i == last ? 1 : 0) + (j == last ? 2 : 0)];
                    int& slot = scratch.lattice_slot[size_t(j) * side + size_t(i)];
                    if (slot < 0) {
                        slot = int(scratch.lattice_values.size());
                        scratch.lattice_touched.push_back(j * side + i);
                        scratch.lattice_values.push_back(
                            eval(x + double(i) / last, y + double(j) / last));
                    }
                    return scratch.lattice_values[size_t(slot)];
                };
                store(x, y, adaptive_square(s, at, last / 2, last / 2, last / 2, 0));
                for (int k : scratch.lattice_touched) scratch.lattice_slot[size_t(k)] = -1;
                scratch.lattice_touched.clear();
                scratch.lattice_values.clear();
            }
        }
        return;
    }
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            if (s.kind == SamplerKind::Center) {
                store(x, y, eval(x + 0.5, y + 0.5));
                continue;
            }
            SampleValue sum;
            if (s.kind == SamplerKind::Statistical) {
                // Welford's running mean and variance per channel; stop once the standard error of
                // the mean, sqrt(variance / n), is below the threshold in every channel.
                double mean[4] = {0, 0, 0, 0}, m2[4] = {0, 0, 0, 0};
                int n = 0;
                const double limit = s.noise_threshold * s.noise_threshold;
                for (;;) {
                    double u = sample_uniform(s.seed, x, y, 2 * uint64_t(n));
                    double v = sample_uniform(s.seed, x, y, 2 * uint64_t(n) + 1);
                    if (n < 16) {
                        // The first 16 are jittered over a 4 x 4 grid: an edge or a detail covering
                        // more than about an eighth of the pixel cannot hide from all of them (four
                        // random samples miss a quarter-pixel detail a third of the time), and the
                        // test that follows, which assumes independent samples, only overestimates
                        // the error of such a stratified set.
                        u = std::min(0.25 * ((n & 3) + u), std::nextafter(1.0, 0.0));
                        v = std::min(0.25 * ((n >> 2) + v), std::nextafter(1.0, 0.0));
                    }
                    const SampleValue r = eval(x + u, y + v);
                    const double values[4] = {r.color.x, r.color.y, r.color.z, r.alpha};
                    ++n;
                    for (int c = 0; c < 4; ++c) {
                        const double d = values[c] - mean[c];
                        mean[c] += d / n;
                        m2[c] += d * (values[c] - mean[c]);
                    }
                    if (n >= s.max_samples) break;
                    if (n >= s.min_samples) {
                        const double worst = std::max({m2[0], m2[1], m2[2], m2[3]});
                        // variance/n = m2/((n-1) n), the unbiased estimate of the mean's variance
                        if (worst <= limit * double(n - 1) * n) break;
                    }
                }
                sum.color = Vec3(mean[0], mean[1], mean[2]);
                sum.alpha = mean[3];
                store(x, y, sum);
                continue;
            }
            fixed_offsets(s, x, y, scratch.offsets);
            const double w = 1.0 / double(scratch.offsets.size());
            for (const Vec2& o : scratch.offsets) accumulate(sum, eval(x + o.x, y + o.y), w);
            store(x, y, sum);
        }
    }
}

}  // namespace vr
