// vrmlray compare A B: golden-image comparison with optional pass/fail thresholds.
#include <iostream>

#include "app/commands.h"
#include "image/compare.h"
#include "image/image.h"

namespace vr {

int run_compare(const CompareCommand& cmd) {
    Image a, b;
    std::string error;
    if (!read_image(cmd.a, a, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitBadInput;
    }
    if (!read_image(cmd.b, b, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitBadInput;
    }
    CompareMetrics metrics;
    if (!compare_images(a, b, cmd.pixel_threshold, metrics, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitBadInput;
    }
    CompareThresholds thresholds;
    thresholds.max_rmse = cmd.max_rmse;
    thresholds.min_psnr = cmd.min_psnr;
    thresholds.min_ssim = cmd.min_ssim;
    thresholds.max_abs = cmd.max_abs;
    thresholds.max_fail_percent = cmd.max_fail_percent;
    thresholds.pixel_threshold = cmd.pixel_threshold;
    std::vector<std::string> failures = failed_thresholds(metrics, thresholds);
    if (cmd.json) {
        std::cout << format_metrics_json(metrics, failures);
    } else {
        std::cout << format_metrics_text(metrics);
        for (const std::string& f : failures) std::cout << "FAIL: " << f << "\n";
    }
    if (!cmd.diff_path.empty()) {
        Image diff = difference_heatmap(a, b);
        if (!write_image(cmd.diff_path, diff, false, error)) {
            std::cerr << "vrmlray: error: " << error << "\n";
            return kExitOutput;
        }
    }
    return failures.empty() ? kExitOk : kExitCompareFailed;
}

}  // namespace vr
