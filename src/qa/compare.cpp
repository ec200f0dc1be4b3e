// Golden-image metrics. See compare.h for the definitions; this file holds the arithmetic.
#include "qa/compare.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <thread>

namespace vr {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- SSIM --------------------------------------------------------------------------------------

constexpr int kWindowRadius = 5;  // 11x11 window
constexpr int kWindowSize = 2 * kWindowRadius + 1;
constexpr double kWindowSigma = 1.5;
constexpr double kK1 = 0.01, kK2 = 0.03, kDynamicRange = 1.0;

// The window along one axis: for output index o, the weights w[o*kWindowSize + k], k < len[o],
// apply to input indices first[o] + k. Weights of each output sum to 1.
struct AxisWindow {
    int count = 0;  // number of window centres along this axis
    std::vector<int> first, len;
    std::vector<double> weights;
};

AxisWindow make_axis_window(int n) {
    std::array<double, kWindowSize> g{};
    for (int k = -kWindowRadius; k <= kWindowRadius; ++k)
        g[k + kWindowRadius] = std::exp(-double(k * k) / (2 * kWindowSigma * kWindowSigma));

    AxisWindow a;
    // Full windows when they fit; otherwise every pixel is a centre and the window is clipped.
    const bool full = n >= kWindowSize;
    a.count = full ? n - 2 * kWindowRadius : n;
    a.first.resize(a.count);
    a.len.resize(a.count);
    a.weights.assign(size_t(a.count) * kWindowSize, 0.0);
    for (int o = 0; o < a.count; ++o) {
        const int centre = full ? o + kWindowRadius : o;
        const int lo = std::max(0, centre - kWindowRadius);
        const int hi = std::min(n - 1, centre + kWindowRadius);
        a.first[o] = lo;
        a.len[o] = hi - lo + 1;
        double sum = 0;
        for (int i = lo; i <= hi; ++i) sum += g[i - centre + kWindowRadius];
        for (int i = lo; i <= hi; ++i)
            a.weights[size_t(o) * kWindowSize + (i - lo)] = g[i - centre + kWindowRadius] / sum;
    }
    return a;
}

// The five windowed moments: E[x], E[y], E[x^2], E[y^2], E[xy].
constexpr int kMoments = 5;

// Computes the SSIM map for output rows [row_begin, row_end) and returns the sum of its values. The
// horizontally filtered input rows live in a ring of kWindowSize rows, since a window spans at most
// that many consecutive rows and windows only move down.
double ssim_rows(const std::vector<double>& x, const std::vector<double>& y, int width,
                 const AxisWindow& wx, const AxisWindow& wy, int row_begin, int row_end) {
    const int cols = wx.count;
    const double c1 = (kK1 * kDynamicRange) * (kK1 * kDynamicRange);
    const double c2 = (kK2 * kDynamicRange) * (kK2 * kDynamicRange);

    std::vector<double> ring(size_t(kWindowSize) * kMoments * cols);
    auto ring_row = [&](int input_row, int moment) {
        return ring.data() + (size_t(input_row % kWindowSize) * kMoments + moment) * cols;
    };
    auto filter_row = [&](int r) {
        const double* xr = x.data() + size_t(r) * width;
        const double* yr = y.data() + size_t(r) * width;
        double* m[kMoments];
        for (int q = 0; q < kMoments; ++q) m[q] = ring_row(r, q);
        for (int o = 0; o < cols; ++o) {
            const double* w = wx.weights.data() + size_t(o) * kWindowSize;
            const double* xs = xr + wx.first[o];
            const double* ys = yr + wx.first[o];
            double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
            for (int k = 0; k < wx.len[o]; ++k) {
                const double a = xs[k], b = ys[k];
                sx += w[k] * a;
                sy += w[k] * b;
                sxx += w[k] * a * a;
                syy += w[k] * b * b;
                sxy += w[k] * a * b;
            }
            m[0][o] = sx, m[1][o] = sy, m[2][o] = sxx, m[3][o] = syy, m[4][o] = sxy;
        }
    };

    std::vector<double> acc(size_t(kMoments) * cols);
    int next_row = row_begin < wy.count ? wy.first[row_begin] : 0;
    double total = 0;
    for (int oy = row_begin; oy < row_end; ++oy) {
        const int lo = wy.first[oy], len = wy.len[oy];
        for (; next_row < lo + len; ++next_row) filter_row(next_row);
        std::fill(acc.begin(), acc.end(), 0.0);
        for (int k = 0; k < len; ++k) {
            const double w = wy.weights[size_t(oy) * kWindowSize + k];
            for (int q = 0; q < kMoments; ++q) {
                const double* src = ring_row(lo + k, q);
                double* dst = acc.data() + size_t(q) * cols;
                for (int o = 0; o < cols; ++o) dst[o] += w * src[o];
            }
        }
        double row_sum = 0;
        for (int o = 0; o < cols; ++o) {
            const double mx = acc[o], my = acc[size_t(cols) + o];
            const double vx = acc[2 * size_t(cols) + o] - mx * mx;
            const double vy = acc[3 * size_t(cols) + o] - my * my;
            const double cxy = acc[4 * size_t(cols) + o] - mx * my;
            row_sum +=
                ((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
        }
        total += row_sum;
    }
    return total;
}

// ---- formatting --------------------------------------------------------------------------------

// Six significant digits, "inf"/"-inf"/"nan" for non-finite values.
std::string short_number(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

}  // namespace

double ssim_luminance(const std::vector<double>& x, const std::vector<double>& y, int width,
                      int height) {
    if (width <= 0 || height <= 0) return 1.0;
    const AxisWindow wx = make_axis_window(width);
    const AxisWindow wy = make_axis_window(height);

    // Output rows are cut into fixed blocks whose sums are added in block order, so the result does
    // not depend on the number of threads.
    constexpr int kBlockRows = 64;
    const int nblocks = (wy.count + kBlockRows - 1) / kBlockRows;
    std::vector<double> block_sums(nblocks, 0.0);
    std::atomic<int> next_block{0};
    auto worker = [&] {
        for (int b; (b = next_block.fetch_add(1)) < nblocks;) {
            const int begin = b * kBlockRows, end = std::min(wy.count, begin + kBlockRows);
            block_sums[b] = ssim_rows(x, y, width, wx, wy, begin, end);
        }
    };
    const size_t work = size_t(wx.count) * size_t(wy.count);
    const int nthreads = work < 100000 ? 1
                                       : int(std::clamp(std::thread::hardware_concurrency(), 1u,
                                                        unsigned(std::max(1, nblocks))));
    std::vector<std::thread> threads;
    for (int t = 1; t < nthreads; ++t) threads.emplace_back(worker);
    worker();
    for (auto& t : threads) t.join();

    double total = 0;
    for (double s : block_sums) total += s;
    return total / (double(wx.count) * double(wy.count));
}

namespace {

// "3 channels (no alpha)"
std::string describe_channels(const Image& image) {
    return std::to_string(image.file_channels) +
           (image.file_channels == 1 ? " channel" : " channels") +
           (image.has_alpha ? " (with alpha)" : " (no alpha)");
}

// Non-empty when both images come from files whose channels differ (idiff fails those too).
std::string channel_mismatch(const Image& a, const Image& b) {
    if (a.file_channels == 0 || b.file_channels == 0) return "";
    if (a.file_channels == b.file_channels && a.has_alpha == b.has_alpha) return "";
    return "channel counts differ: the reference has " + describe_channels(a) + ", the result " +
           describe_channels(b) + " (RGB compared)";
}

}  // namespace

bool compare_images(const Image& a, const Image& b, double pixel_threshold, CompareMetrics& out,
                    std::string& error) {
    CompareThresholds t;
    t.pixel_threshold = pixel_threshold;
    return compare_images(a, b, t, out, error);
}

bool compare_images(const Image& a, const Image& b, const CompareThresholds& t, CompareMetrics& out,
                    std::string& error) {
    if (a.width != b.width || a.height != b.height) {
        error = "image sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " against " + std::to_string(b.width) + "x" + std::to_string(b.height);
        return false;
    }
    if (a.width <= 0 || a.height <= 0) {
        error = "the images are empty";
        return false;
    }
    const int w = a.width, h = a.height;
    const size_t npix = size_t(w) * size_t(h);
    // A filler alpha of 1 in an image without one is no value to compare.
    const int nch = a.has_alpha && b.has_alpha ? 4 : 3;
    const double fail = t.fail.value_or(kIdiffDefaultFail);
    const double warn = t.warn.value_or(kIdiffDefaultWarn);
    std::vector<double> lum_a(npix), lum_b(npix);

    double sum_sq = 0, sum_abs = 0, max_abs = 0;
    size_t over_pixel = 0, over_fail = 0, over_warn = 0;
    for (int row = 0; row < h; ++row) {
        double row_sq = 0, row_abs = 0;
        for (int col = 0; col < w; ++col) {
            const size_t p = size_t(row) * w + col;
            const float* pa = a.rgba.data() + p * 4;
            const float* pb = b.rgba.data() + p * 4;
            double pixel_max = 0;
            for (int c = 0; c < nch; ++c) {
                double d = std::fabs(double(pa[c]) - double(pb[c]));
                if (!std::isfinite(d)) d = kInf;
                row_sq += d * d;
                row_abs += d;
                pixel_max = std::max(pixel_max, d);
            }
            max_abs = std::max(max_abs, pixel_max);
            over_pixel += pixel_max > t.pixel_threshold;
            over_fail += pixel_max > fail;
            over_warn += pixel_max > warn;
            lum_a[p] = 0.2126 * pa[0] + 0.7152 * pa[1] + 0.0722 * pa[2];
            lum_b[p] = 0.2126 * pb[0] + 0.7152 * pb[1] + 0.0722 * pb[2];
        }
        sum_sq += row_sq;
        sum_abs += row_abs;
    }
    const double nsamples = double(nch) * double(npix);
    const double mse = sum_sq / nsamples;
    auto percent = [&](size_t count) { return 100.0 * double(count) / double(npix); };

    CompareMetrics m;
    m.width = w;
    m.height = h;
    m.channels = nch;
    m.channel_mismatch = channel_mismatch(a, b);
    m.pixel_threshold = t.pixel_threshold;
    m.rmse = std::sqrt(mse);
    m.psnr = mse > 0 ? 10.0 * std::log10(1.0 / mse) : kInf;
    m.mean_abs = sum_abs / nsamples;
    m.max_abs = max_abs;
    m.fail_percent = percent(over_pixel);
    m.idiff_fail = fail;
    m.idiff_fail_percent = percent(over_fail);
    m.idiff_warn = warn;
    m.idiff_warn_percent = percent(over_warn);
    m.ssim = ssim_luminance(lum_a, lum_b, w, h);
    out = std::move(m);
    return true;
}

namespace {

// idiff's test on the pixels over `limit` and the largest difference; `what` is "fail" or "warn".
void idiff_test(const CompareMetrics& m, double limit, double over_percent,
                const std::optional<double>& percent, const std::optional<double>& hard,
                const std::string& what, const std::string& note, std::vector<std::string>& out) {
    const double allowed = percent.value_or(0.0);
    if (!(over_percent <= allowed))
        out.push_back(short_number(over_percent) + "% of pixels differ by more than " +
                      short_number(limit) + " > " + short_number(allowed) + "% (" + note + ")");
    if (hard && !(m.max_abs <= *hard))
        out.push_back("max abs diff " + short_number(m.max_abs) + " > " + short_number(*hard) +
                      " (--hard" + what + ")");
}

}  // namespace

std::vector<std::string> failed_thresholds(const CompareMetrics& m, const CompareThresholds& t) {
    std::vector<std::string> failures;
    if (!m.channel_mismatch.empty()) failures.push_back(m.channel_mismatch);
    // Written as !(ok) so that a NaN metric fails.
    auto above = [&](const char* what, double value, const std::optional<double>& limit,
                     const char* option, const char* unit) {
        if (limit && !(value <= *limit))
            failures.push_back(std::string(what) + " " + short_number(value) + unit + " > " +
                               short_number(*limit) + unit + " (" + option + ")");
    };
    auto below = [&](const char* what, double value, const std::optional<double>& limit,
                     const char* option, const char* unit) {
        if (limit && !(value >= *limit))
            failures.push_back(std::string(what) + " " + short_number(value) + unit + " < " +
                               short_number(*limit) + unit + " (" + option + ")");
    };
    above("RMSE", m.rmse, t.max_rmse, "--max-rmse", "");
    below("PSNR", m.psnr, t.min_psnr, "--min-psnr", " dB");
    below("SSIM", m.ssim, t.min_ssim, "--min-ssim", "");
    above("max abs diff", m.max_abs, t.max_abs, "--max-abs", "");
    above("failed pixels", m.fail_percent, t.max_fail_percent, "--max-fail-percent", "%");

    const bool idiff_set = t.fail || t.failpercent || t.hardfail;
    const bool any_set =
        idiff_set || t.max_rmse || t.min_psnr || t.min_ssim || t.max_abs || t.max_fail_percent;
    if (idiff_set || !any_set)
        idiff_test(m, m.idiff_fail, m.idiff_fail_percent, t.failpercent, t.hardfail, "fail",
                   idiff_set ? "--fail, --failpercent"
                             : "no threshold given: idiff's default --fail 1e-06 --failpercent 0",
                   failures);
    return failures;
}

std::vector<std::string> warned_thresholds(const CompareMetrics& m, const CompareThresholds& t) {
    std::vector<std::string> warnings;
    if (t.warn || t.warnpercent || t.hardwarn)
        idiff_test(m, m.idiff_warn, m.idiff_warn_percent, t.warnpercent, t.hardwarn, "warn",
                   "--warn, --warnpercent", warnings);
    return warnings;
}

std::string format_metrics_text(const CompareMetrics& m) {
    std::string s;
    auto line = [&](const char* label, const std::string& value) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%-15s", label);
        s += buf + value + "\n";
    };
    line("size", std::to_string(m.width) + " x " + std::to_string(m.height));
    line("channels", m.channels == 4 ? "4 (RGBA)" : "3 (RGB)");
    line("RMSE", short_number(m.rmse));
    line("PSNR", short_number(m.psnr) + " dB");
    line("mean abs diff", short_number(m.mean_abs));
    line("max abs diff", short_number(m.max_abs));
    line("SSIM", short_number(m.ssim));
    line("failed pixels", short_number(m.fail_percent) + " % (difference > " +
                              short_number(m.pixel_threshold) + ")");
    return s;
}

std::string format_metrics_json(const CompareMetrics& m, const std::vector<std::string>& failures,
                                const std::vector<std::string>& warnings) {
    // JSON has no infinity or NaN; a string says which it was.
    auto number = [](double v) -> nlohmann::ordered_json {
        if (std::isfinite(v)) return v;
        return std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
    };
    nlohmann::ordered_json j;
    j["width"] = m.width;
    j["height"] = m.height;
    j["channels"] = m.channels;
    j["rmse"] = number(m.rmse);
    j["psnr"] = number(m.psnr);
    j["mean_abs"] = number(m.mean_abs);
    j["max_abs"] = number(m.max_abs);
    j["ssim"] = number(m.ssim);
    j["fail_percent"] = number(m.fail_percent);
    j["pixel_threshold"] = number(m.pixel_threshold);
    j["idiff_fail"] = number(m.idiff_fail);
    j["idiff_fail_percent"] = number(m.idiff_fail_percent);
    j["idiff_warn"] = number(m.idiff_warn);
    j["idiff_warn_percent"] = number(m.idiff_warn_percent);
    j["pass"] = failures.empty();
    j["failures"] = failures;
    j["warnings"] = warnings;
    // Invalid UTF-8 in a message (a file name) is replaced, not thrown on.
    return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

void heatmap_color(double d, float rgb[3]) {
    // Stops at t = 0, 1/4, 1/2, 3/4, 1.
    static constexpr float kStops[5][3] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}};
    double t;
    if (std::isnan(d) || d >= kHeatmapMaxDiff) {
        t = 1;
    } else if (d <= kHeatmapMinDiff) {
        t = 0;
    } else {
        t = std::log10(d / kHeatmapMinDiff) / std::log10(kHeatmapMaxDiff / kHeatmapMinDiff);
    }
    const double pos = std::clamp(t, 0.0, 1.0) * 4.0;
    const int i = std::min(3, int(pos));
    const double f = pos - i;
    for (int c = 0; c < 3; ++c) rgb[c] = float((1.0 - f) * kStops[i][c] + f * kStops[i + 1][c]);
}

Image difference_heatmap(const Image& a, const Image& b) {
    if (a.width != b.width || a.height != b.height) return Image();
    Image out(a.width, a.height);
    const int nch = a.has_alpha && b.has_alpha ? 4 : 3;
    const size_t npix = size_t(a.width) * size_t(a.height);
    for (size_t p = 0; p < npix; ++p) {
        const float* pa = a.rgba.data() + p * 4;
        const float* pb = b.rgba.data() + p * 4;
        double d = 0;
        for (int c = 0; c < nch; ++c) {
            double dc = std::fabs(double(pa[c]) - double(pb[c]));
            if (!std::isfinite(dc)) dc = kInf;
            d = std::max(d, dc);
        }
        float* po = out.rgba.data() + p * 4;
        heatmap_color(d, po);
        po[3] = 1.0f;
    }
    return out;
}

}  // namespace vr
