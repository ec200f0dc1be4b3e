// vrmlray compare A B: golden-image comparison with pass/fail thresholds (idiff's 1e-6 when none is
// given). Warnings are printed and exit 0, as idiff's are a pass with a remark; failures exit 1.
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
    CompareThresholds thresholds;
    thresholds.max_rmse = cmd.max_rmse;
    thresholds.min_psnr = cmd.min_psnr;
    thresholds.min_ssim = cmd.min_ssim;
    thresholds.max_abs = cmd.max_abs;
    thresholds.max_fail_percent = cmd.max_fail_percent;
    thresholds.fail = cmd.fail;
    thresholds.failpercent = cmd.failpercent;
    thresholds.hardfail = cmd.hardfail;
    thresholds.warn = cmd.warn;
    thresholds.warnpercent = cmd.warnpercent;
    thresholds.hardwarn = cmd.hardwarn;
    thresholds.pixel_threshold = cmd.pixel_threshold;
    CompareMetrics metrics;
    if (!compare_images(a, b, thresholds, metrics, error)) {
        std::cerr << "vrmlray: error: " << error << "\n";
        return kExitBadInput;
    }
    const std::vector<std::string> failures = failed_thresholds(metrics, thresholds);
    const std::vector<std::string> warnings = warned_thresholds(metrics, thresholds);
    if (cmd.json) {
        std::cout << format_metrics_json(metrics, failures, warnings);
    } else {
        std::cout << format_metrics_text(metrics);
        for (const std::string& w : warnings) std::cout << "WARNING: " << w << "\n";
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
