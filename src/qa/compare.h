// Golden-image comparison (docs/golden-tests.md): error metrics between two images of the same
// size, pass/fail thresholds on them, their text and JSON reports, and a difference heat-map.
//
// All metrics but SSIM are over every channel as stored, alpha included (R, G, B, A; R, G, B when
// an image has no alpha). Images whose files had different channel counts fail (RGB against RGBA).
//   rmse          sqrt of the mean squared difference over all samples
//   psnr          10 log10(1 / MSE), peak 1 (integer files read back in [0,1]); +infinity when
//                 the images are identical, printed as "inf"
//   mean_abs      mean absolute difference over all samples
//   max_abs       largest absolute difference over all samples
//   ssim          mean SSIM (Wang, Bovik, Sheikh, Simoncelli 2004) on the luminance
//                 Y = 0.2126 R + 0.7152 G + 0.0722 B (Rec. 709 weights on the values as stored),
//                 11x11 Gaussian window of sigma 1.5 normalised to sum 1, K1 = 0.01, K2 = 0.03,
//                 L = 1, averaged over the window positions that lie fully inside the image.
//                 In a dimension smaller than 11 pixels every pixel is a window centre and the
//                 window is clipped to the image and renormalised to sum 1 (the window is
//                 separable, so this is done per axis). No automatic downsampling (unlike the
//                 2009 ssim.m), so the value is the 2004 paper's ssim_index at full resolution.
//                 SSIM is a measure of perceived structure, so alpha does not enter it.
//   fail_percent  percentage (0..100) of pixels whose largest channel absolute difference
//                 exceeds the pixel threshold (likewise idiff_fail_percent and idiff_warn_percent
//                 over idiff's --fail and --warn)
// A sample difference that is not finite (a NaN or infinity in either image) counts as an
// infinite difference, so such images never pass a threshold.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "image/image.h"

namespace vr {

struct CompareMetrics {
    double rmse = 0;
    double psnr = 0;  // dB; +infinity when identical
    double mean_abs = 0;
    double max_abs = 0;
    double ssim = 1;
    double fail_percent = 0;  // 0..100
    int width = 0;
    int height = 0;
    double pixel_threshold = 1.0 / 255;  // the threshold fail_percent was counted with
    int channels = 4;                    // channels compared: 4 (RGBA) or 3 (RGB)
    std::string channel_mismatch;        // non-empty when the images' channel counts differ
    // Percentages of pixels over idiff's --fail and --warn thresholds (the values compared with).
    double idiff_fail = 1e-6, idiff_fail_percent = 0;
    double idiff_warn = 1e-6, idiff_warn_percent = 0;
};

// Unset thresholds are not checked. A comparison passes when every set threshold holds (<= for
// maxima, >= for minima); a NaN metric fails every threshold on it. A channel-count mismatch
// always fails.
//
// OpenImageIO idiff's test, with its meanings and defaults: a pixel fails when a channel differs by
// more than `fail` (default 1e-6); the comparison fails when more than `failpercent` percent of the
// pixels fail (default 0) or any channel differs by more than `hardfail` (default infinity). It is
// checked when one of those three is set, and also when no threshold at all is set: then the images
// pass only when every value agrees to 1e-6, as with idiff. The warning test is the same with
// `warn`, `warnpercent`, `hardwarn`, checked when one of them is set; a warning never fails.
struct CompareThresholds {
    std::optional<double> max_rmse, min_psnr, min_ssim, max_abs, max_fail_percent;
    std::optional<double> fail, failpercent, hardfail;
    std::optional<double> warn, warnpercent, hardwarn;
    double pixel_threshold = 1.0 / 255;
};

// idiff's defaults, where CompareThresholds leaves them unset.
inline constexpr double kIdiffDefaultFail = 1e-6;
inline constexpr double kIdiffDefaultWarn = 1e-6;

// Fills `out` with the metrics of `a` against `b`, counting failed pixels over
// thresholds.pixel_threshold, fail and warn. Returns false and sets `error` when the sizes differ
// or an image is empty.
bool compare_images(const Image& a, const Image& b, const CompareThresholds& thresholds,
                    CompareMetrics& out, std::string& error);
// The same, with only the pixel threshold set.
bool compare_images(const Image& a, const Image& b, double pixel_threshold, CompareMetrics& out,
                    std::string& error);

// Mean SSIM of two luminance planes (row-major, width x height, both the same size), as described
// above.
double ssim_luminance(const std::vector<double>& x, const std::vector<double>& y, int width,
                      int height);

// One human-readable line per failed threshold, e.g. "RMSE 0.0213 > 0.01 (--max-rmse)"; empty =
// pass. `metrics` must have been computed with the same thresholds.
std::vector<std::string> failed_thresholds(const CompareMetrics& metrics,
                                           const CompareThresholds& thresholds);
// The same for idiff's warning test.
std::vector<std::string> warned_thresholds(const CompareMetrics& metrics,
                                           const CompareThresholds& thresholds);

// Multi-line, aligned report for the terminal; ends with a newline.
std::string format_metrics_text(const CompareMetrics& metrics);

// One JSON object: size, channels, every metric at full precision (numbers read back as the same
// double; psnr as the string "inf" when identical, other non-finite values as strings "inf",
// "-inf", "nan"), the pixel threshold, "pass", and the "failures" and "warnings" lines. Ends with a
// newline.
std::string format_metrics_json(const CompareMetrics& metrics,
                                const std::vector<std::string>& failures,
                                const std::vector<std::string>& warnings = {});

// Heat-map scale: the per-pixel difference d (largest channel absolute difference, alpha included)
// is placed on a logarithmic ramp, t = log10(d / kHeatmapMinDiff) / log10(kHeatmapMaxDiff /
// kHeatmapMinDiff) clamped to [0,1], so each decade has its own colour:
//   d <= 1e-4 black, 1e-3 blue, 1e-2 red, 1e-1 yellow, >= 1 white (and non-finite d white),
// linearly interpolated in RGB in between. d = 0 is black. 8-bit rounding (1/255 ~ 3.9e-3) lands
// between blue and red.
inline constexpr double kHeatmapMinDiff = 1e-4;
inline constexpr double kHeatmapMaxDiff = 1.0;

// The ramp colour (RGB in [0,1]) of a difference d.
void heatmap_color(double d, float rgb[3]);

// A same-size opaque image (alpha 1) of the ramp colours of the per-pixel differences; an empty
// Image when the sizes differ.
Image difference_heatmap(const Image& a, const Image& b);

}  // namespace vr
