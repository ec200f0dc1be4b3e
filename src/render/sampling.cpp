#include "render/sampling.h"

#include <cmath>

namespace vr {
namespace {

// Sample positions of one pattern cell in sixteenths of the cell: the rotated grid of four (each
// row and column holds one sample, the grid turned by atan(1/2)) and the eight rooks (no two share
// a row or a column of the 8 x 8 lattice). Both patterns are the ones graphics hardware uses for
// 4x and 8x multisampling, shifted into [0, 16).
constexpr int kRgss[4][2] = {{6, 2}, {14, 6}, {2, 10}, {10, 14}};
constexpr int kRooks8[8][2] = {{9, 5},  {7, 11}, {13, 9},  {5, 3},
                               {3, 13}, {1, 7},  {11, 15}, {15, 1}};

// m with m * m * base == spp, or 0.
int tiling(int spp, int base) {
    if (spp % base != 0) return 0;
    const int m = int(std::lround(std::sqrt(double(spp / base))));
    return m * m * base == spp ? m : 0;
}

template <size_t N>
void tiled_pattern(const int (&pattern)[N][2], int m, std::vector<Vec2>& out) {
    const double cell = 1.0 / m;
    for (int b = 0; b < m; ++b)
        for (int a = 0; a < m; ++a)
            for (const auto& p : pattern)
                out.emplace_back((a + p[0] / 16.0) * cell, (b + p[1] / 16.0) * cell);
}

}  // namespace

int PixelSampler::fixed_samples_per_pixel() const {
    switch (kind) {
        case SamplerKind::Center:
            return 1;
        case SamplerKind::Grid:
        case SamplerKind::Jitter:
            return n * n;
        case SamplerKind::Rgss:
            return 4 * n * n;
        case SamplerKind::Rooks8:
            return 8 * n * n;
        default:
            return 0;
    }
}

void fixed_offsets(const PixelSampler& s, int px, int py, std::vector<Vec2>& out) {
    out.clear();
    const double cell = 1.0 / s.n;
    switch (s.kind) {
        case SamplerKind::Center:
            out.emplace_back(0.5, 0.5);
            break;
        case SamplerKind::Grid:
            for (int b = 0; b < s.n; ++b)
                for (int a = 0; a < s.n; ++a) out.emplace_back((a + 0.5) * cell, (b + 0.5) * cell);
            break;
        case SamplerKind::Jitter:
            for (int b = 0; b < s.n; ++b) {
                for (int a = 0; a < s.n; ++a) {
                    const uint64_t k = 2 * (uint64_t(b) * s.n + a);
                    const double u = sample_uniform(s.seed, px, py, k),
                                 v = sample_uniform(s.seed, px, py, k + 1);
                    // (a + u) * cell can round up to the cell's far edge; min() keeps the last one
                    // inside the pixel
                    out.emplace_back(std::min((a + u) * cell, std::nextafter(1.0, 0.0)),
                                     std::min((b + v) * cell, std::nextafter(1.0, 0.0)));
                }
            }
            break;
        case SamplerKind::Rgss:
            tiled_pattern(kRgss, s.n, out);
            break;
        case SamplerKind::Rooks8:
            tiled_pattern(kRooks8, s.n, out);
            break;
        default:
            break;
    }
}

std::optional<SamplerKind> sampler_kind(const std::string& name) {
    for (size_t k = 0; k < kSamplerNames.size(); ++k)
        if (name == kSamplerNames[k]) return SamplerKind(k);
    return std::nullopt;
}

std::string sampler_names(const std::string& separator) {
    std::string names;
    for (const char* name : kSamplerNames) names += (names.empty() ? "" : separator) + name;
    return names;
}

bool make_sampler(const RenderOptions& options, PixelSampler& sampler, std::string& error) {
    const SamplerKind kind = options.sampler;
    const std::string name = sampler_name(options.sampler);
    const int spp = options.spp;
    sampler = PixelSampler();
    sampler.seed = options.seed;
    if (spp < 1) {
        error = "--spp must be at least 1 (got " + std::to_string(spp) + ")";
        return false;
    }
    auto need = [&](const std::string& what) {
        error = "sampler '" + name + "' needs " + what + ", got --spp " + std::to_string(spp);
        return false;
    };
    if (kind == SamplerKind::Center || kind == SamplerKind::Grid || kind == SamplerKind::Jitter) {
        if (kind == SamplerKind::Center && spp == 1) {
            sampler.kind = SamplerKind::Center;
            return true;
        }
        const int n = tiling(spp, 1);
        if (n == 0) return need("a square number of samples per pixel (1, 4, 9, 16, ...)");
        // center with --spp > 1 is the grid: docs/manual.md makes center the default for spp 1
        // only.
        sampler.kind = kind == SamplerKind::Jitter ? SamplerKind::Jitter : SamplerKind::Grid;
        sampler.n = n;
        return true;
    }
    if (kind == SamplerKind::Rgss || kind == SamplerKind::Rooks8) {
        const int base = kind == SamplerKind::Rgss ? 4 : 8;
        // --spp 1 (the default) means the pattern once.
        const int n = spp == 1 ? 1 : tiling(spp, base);
        if (n == 0) {
            const std::string b = std::to_string(base);
            return need(b + " m^2 samples per pixel (the pattern tiled m x m: " + b + ", " +
                        std::to_string(4 * base) + ", " + std::to_string(9 * base) + ", ...)");
        }
        sampler.kind = kind == SamplerKind::Rgss ? SamplerKind::Rgss : SamplerKind::Rooks8;
        sampler.n = n;
        return true;
    }
    if (kind == SamplerKind::Quincunx || kind == SamplerKind::Adaptive) {
        if (spp != 1)
            return need(std::string("no --spp (it ") +
                        (kind == SamplerKind::Quincunx
                             ? "traces the centre and shares the corners, about 2 rays per pixel"
                             : "spends what --adaptive-threshold asks for") +
                        ")");
        if (!(options.adaptive_threshold >= 0.0)) {
            error = "--adaptive-threshold must be at least 0";
            return false;
        }
        if (options.adaptive_depth < 0 || options.adaptive_depth > 6) {
            error = "--adaptive-depth must be between 0 and 6 (got " +
                    std::to_string(options.adaptive_depth) + ")";
            return false;
        }
        sampler.kind =
            kind == SamplerKind::Quincunx ? SamplerKind::Quincunx : SamplerKind::Adaptive;
        sampler.adaptive_threshold = options.adaptive_threshold;
        sampler.adaptive_depth = kind == SamplerKind::Quincunx ? 0 : options.adaptive_depth;
        return true;
    }
    if (kind == SamplerKind::Statistical) {
        if (!(options.noise_threshold > 0.0)) {
            error = "--noise-threshold must be greater than 0";
            return false;
        }
        sampler.kind = SamplerKind::Statistical;
        sampler.noise_threshold = options.noise_threshold;
        // --spp is the cap; left at 1 it means the default cap.
        if (spp != 1 && spp < sampler.min_samples)
            return need("at least " + std::to_string(sampler.min_samples) +
                        " as its cap (it starts with a jittered 4 x 4 set)");
        sampler.max_samples = spp == 1 ? kDefaultStatisticalCap : spp;
        return true;
    }
    return false;  // unreachable: every kind is handled above
}

}  // namespace vr
