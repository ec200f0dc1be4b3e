// Pixel samplers (SPEC section 7). A sampler decides where in a pixel to trace and how many times,
// and averages the results (box filter over the pixel). Implemented: `center` and `grid`; the
// others named by the SPEC are later work and are rejected by make_sampler with an error.
#pragma once
#include <cmath>
#include <string>

#include "core/math.h"
#include "render/options.h"

namespace vr {

// What one camera ray brings back: colour, and the weight with which the background reaches it.
struct SampleValue {
    Vec3 color{0.0};
    double background = 1.0;
};

enum class SamplerKind : uint8_t { Center, Grid };

struct PixelSampler {
    SamplerKind kind = SamplerKind::Center;
    int n = 1;  // grid: n x n samples

    int samples_per_pixel() const { return kind == SamplerKind::Grid ? n * n : 1; }

    // Traces the pixel whose top-left corner is (px, py) (pixel units, y down) through
    // eval(x, y) -> SampleValue and returns the average. Deterministic: no random numbers.
    template <class Eval>
    SampleValue pixel(int px, int py, Eval&& eval) const {
        if (kind == SamplerKind::Center) return eval(px + 0.5, py + 0.5);
        SampleValue sum;
        sum.background = 0.0;
        const double step = 1.0 / n;
        for (int b = 0; b < n; ++b) {
            for (int a = 0; a < n; ++a) {
                SampleValue s = eval(px + (a + 0.5) * step, py + (b + 0.5) * step);
                sum.color += s.color;
                sum.background += s.background;
            }
        }
        const double inv = 1.0 / (double(n) * n);
        sum.color *= inv;
        sum.background *= inv;
        return sum;
    }
};

// From options.sampler and options.spp. `center` with spp > 1 means the grid (the SPEC makes center
// the default for spp 1 only); grid needs a square spp (1, 4, 9, ...).
bool make_sampler(const RenderOptions& options, PixelSampler& sampler, std::string& error);

}  // namespace vr
