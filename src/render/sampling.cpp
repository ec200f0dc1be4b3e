#include "render/sampling.h"

#include <cmath>

namespace vr {

bool make_sampler(const RenderOptions& options, PixelSampler& sampler, std::string& error) {
    const std::string& name = options.sampler;
    if (options.spp < 1) {
        error = "--spp must be at least 1 (got " + std::to_string(options.spp) + ")";
        return false;
    }
    if (name == "center" || name == "grid") {
        if (name == "center" && options.spp == 1) {
            sampler.kind = SamplerKind::Center;
            sampler.n = 1;
            return true;
        }
        int n = int(std::lround(std::sqrt(double(options.spp))));
        if (n * n != options.spp) {
            error = "sampler '" + name +
                    "' needs a square number of samples per pixel (1, 4, 9, 16, ...), got --spp " +
                    std::to_string(options.spp);
            return false;
        }
        sampler.kind = SamplerKind::Grid;
        sampler.n = n;
        return true;
    }
    if (name == "rgss" || name == "rooks8" || name == "quincunx" || name == "jitter" ||
        name == "adaptive" || name == "statistical") {
        error = "sampler '" + name + "' is not implemented yet (available: center, grid)";
        return false;
    }
    error = "unknown sampler '" + name +
            "' (known: center, grid, rgss, rooks8, quincunx, jitter, adaptive, statistical)";
    return false;
}

}  // namespace vr
