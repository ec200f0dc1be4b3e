// Golden-image metrics: closed forms, an independent brute-force SSIM, thresholds and reports.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "qa/compare.h"

namespace vr {
namespace {

// Smooth structure plus noise, values in about [0,1]; deterministic.
Image test_image(int w, int h, unsigned seed) {
    Image im(w, h);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> noise(-0.1f, 0.1f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = im.pixel(x, y);
            const float base = 0.5f + 0.3f * std::sin(0.3f * x) * std::cos(0.2f * y);
            p[0] = base + noise(rng);
            p[1] = 0.8f * base + noise(rng);
            p[2] = 1.0f - base + noise(rng);
            p[3] = 1.0f;
        }
    return im;
}

// A different image of related structure: contrast change, offset, a shift of the green channel,
// noise.
Image transformed(const Image& a, unsigned seed) {
    Image b = a;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            const float* pa = a.pixel(x, y);
            float* pb = b.pixel(x, y);
            pb[0] = 0.7f * pa[0] + 0.1f + noise(rng);
            pb[1] = a.pixel(std::min(x + 1, a.width - 1), y)[1];
            pb[2] = pa[2] * pa[2];
        }
    return b;
}

// Direct SSIM: a 2D Gaussian window normalised in 2D over the part of the 11x11 square inside the
// image, centred moments computed from their definition. Window centres as compare.h describes.
double brute_force_ssim(const Image& a, const Image& b) {
    const int w = a.width, h = a.height;
    auto lum = [](const Image& im, int x, int y) {
        const float* p = im.pixel(x, y);
        return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    };
    auto centres = [](int n) {
        std::vector<int> c;
        if (n >= 11) {
            for (int i = 5; i + 5 < n; ++i) c.push_back(i);
        } else {
            for (int i = 0; i < n; ++i) c.push_back(i);
        }
        return c;
    };
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    double total = 0;
    size_t count = 0;
    for (int cy : centres(h))
        for (int cx : centres(w)) {
            double wsum = 0, mx = 0, my = 0;
            for (int dy = -5; dy <= 5; ++dy)
                for (int dx = -5; dx <= 5; ++dx) {
                    const int x = cx + dx, y = cy + dy;
                    if (x < 0 || y < 0 || x >= w || y >= h) continue;
                    const double g = std::exp(-(dx * dx + dy * dy) / (2 * 1.5 * 1.5));
                    wsum += g;
                    mx += g * lum(a, x, y);
                    my += g * lum(b, x, y);
                }
            mx /= wsum;
            my /= wsum;
            double vx = 0, vy = 0, cov = 0;
            for (int dy = -5; dy <= 5; ++dy)
                for (int dx = -5; dx <= 5; ++dx) {
                    const int x = cx + dx, y = cy + dy;
                    if (x < 0 || y < 0 || x >= w || y >= h) continue;
                    const double g = std::exp(-(dx * dx + dy * dy) / (2 * 1.5 * 1.5)) / wsum;
                    const double ex = lum(a, x, y) - mx, ey = lum(b, x, y) - my;
                    vx += g * ex * ex;
                    vy += g * ey * ey;
                    cov += g * ex * ey;
                }
            total +=
                ((2 * mx * my + c1) * (2 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
            ++count;
        }
    return total / double(count);
}

CompareMetrics compare_ok(const Image& a, const Image& b, double threshold = 1.0 / 255) {
    CompareMetrics m;
    std::string error;
    EXPECT_TRUE(compare_images(a, b, threshold, m, error)) << error;
    return m;
}

TEST(CompareTest, IdenticalImages) {
    const Image a = test_image(37, 23, 1);
    const CompareMetrics m = compare_ok(a, a);
    EXPECT_EQ(m.rmse, 0.0);
    EXPECT_EQ(m.mean_abs, 0.0);
    EXPECT_EQ(m.max_abs, 0.0);
    EXPECT_EQ(m.fail_percent, 0.0);
    EXPECT_TRUE(std::isinf(m.psnr) && m.psnr > 0);
    EXPECT_DOUBLE_EQ(m.ssim, 1.0);
    EXPECT_EQ(m.width, 37);
    EXPECT_EQ(m.height, 23);
    EXPECT_NE(format_metrics_text(m).find("inf dB"), std::string::npos);
    EXPECT_EQ(nlohmann::json::parse(format_metrics_json(m, {}))["psnr"], "inf");
}

TEST(CompareTest, ConstantOffset) {
    // Dyadic values so that a + d is exact in float.
    Image a(20, 15);
    for (size_t i = 0; i < a.rgba.size(); ++i) a.rgba[i] = float(i % 64) / 128.0f;
    for (double d : {0.125, 0.0078125, 0.5}) {
        Image b = a;
        // Every channel, alpha included, so that every sample differs by d.
        for (size_t i = 0; i < b.rgba.size(); ++i) b.rgba[i] += float(d);
        const CompareMetrics m = compare_ok(a, b);
        EXPECT_DOUBLE_EQ(m.rmse, d);
        EXPECT_DOUBLE_EQ(m.mean_abs, d);
        EXPECT_DOUBLE_EQ(m.max_abs, d);
        EXPECT_NEAR(m.psnr, -20.0 * std::log10(d), 1e-12);
        EXPECT_EQ(m.fail_percent, 100.0);
    }
}

TEST(CompareTest, SsimMatchesBruteForce) {
    struct Size {
        int w, h;
    };
    // Full windows, a large image run on several threads, and images narrower than the window.
    for (Size s :
         {Size{40, 30}, Size{400, 300}, Size{7, 20}, Size{25, 4}, Size{3, 3}, Size{11, 11}}) {
        const Image a = test_image(s.w, s.h, 11 + s.w);
        const Image b = transformed(a, 5 + s.h);
        const CompareMetrics m = compare_ok(a, b);
        const double expected = brute_force_ssim(a, b);
        EXPECT_NEAR(m.ssim, expected, 1e-9) << s.w << "x" << s.h;
        EXPECT_LT(m.ssim, 0.999) << s.w << "x" << s.h;
        EXPECT_GT(m.ssim, 0.0) << s.w << "x" << s.h;
        // Symmetric in its arguments.
        EXPECT_NEAR(compare_ok(b, a).ssim, m.ssim, 1e-12);
    }
}

TEST(CompareTest, SsimOfConstantImagesIsTheLuminanceTerm) {
    Image a(30, 20), b(30, 20);
    for (size_t i = 0; i < a.rgba.size(); ++i) {
        a.rgba[i] = 0.5f;
        b.rgba[i] = 0.25f;
    }
    const double c1 = 1e-4;
    const double expected = (2 * 0.5 * 0.25 + c1) / (0.25 + 0.0625 + c1);
    EXPECT_NEAR(compare_ok(a, b).ssim, expected, 1e-12);
}

TEST(CompareTest, SsimUsesRec709Luminance) {
    // Moving colour between channels at equal luminance leaves SSIM at 1 but changes RMSE.
    Image a(16, 16), b(16, 16);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            const float v = float((x * 3 + y * 5) % 17) / 32.0f;
            float* pa = a.pixel(x, y);
            float* pb = b.pixel(x, y);
            pa[0] = pa[1] = pa[2] = v;
            pb[0] = v + 0.7152f * 0.125f;
            pb[1] = v - 0.2126f * 0.125f;
            pb[2] = v;
        }
    const CompareMetrics m = compare_ok(a, b);
    EXPECT_NEAR(m.ssim, 1.0, 1e-6);
    EXPECT_GT(m.rmse, 0.01);
}

TEST(CompareTest, SizeMismatchIsAnError) {
    CompareMetrics m;
    std::string error;
    EXPECT_FALSE(compare_images(Image(10, 10), Image(10, 11), 1.0 / 255, m, error));
    EXPECT_NE(error.find("10x10"), std::string::npos) << error;
    EXPECT_NE(error.find("10x11"), std::string::npos) << error;
    EXPECT_TRUE(difference_heatmap(Image(4, 4), Image(5, 4)).rgba.empty());
}

TEST(CompareTest, FailPercentCountsPixelsOverTheThreshold) {
    Image a(10, 10);
    for (size_t i = 0; i < a.rgba.size(); ++i) a.rgba[i] = 0.5f;
    Image b = a;
    b.pixel(0, 0)[0] += 0.01f;  // three pixels over 1/255 in one channel
    b.pixel(5, 3)[1] -= 0.02f;
    b.pixel(9, 9)[2] += 0.5f;
    b.pixel(1, 0)[0] += 0.003f;  // two under
    b.pixel(2, 0)[2] -= 0.003f;
    b.pixel(4, 4)[3] = 0.0f;  // and one over in alpha alone
    const CompareMetrics m = compare_ok(a, b);
    EXPECT_DOUBLE_EQ(m.fail_percent, 4.0);
    EXPECT_NEAR(m.max_abs, 0.5, 1e-7);
    EXPECT_DOUBLE_EQ(compare_ok(a, b, 0.1).fail_percent, 2.0);
    EXPECT_DOUBLE_EQ(compare_ok(a, b, 0.001).fail_percent, 6.0);
}

// Regression: an image whose alpha alone changed passed --max-abs 0 (alpha was ignored).
TEST(CompareTest, AlphaIsComparedInEveryFigureButSsim) {
    const Image a = test_image(20, 10, 3);
    Image b = a;
    for (int x = 0; x < 20; ++x) b.pixel(x, 0)[3] = 0.0f;  // 20 of 200 pixels: alpha 1 -> 0
    const CompareMetrics m = compare_ok(a, b);
    EXPECT_EQ(m.channels, 4);
    EXPECT_EQ(m.max_abs, 1.0);
    EXPECT_DOUBLE_EQ(m.fail_percent, 10.0);
    // 20 samples of 800 differ by 1.
    EXPECT_DOUBLE_EQ(m.mean_abs, 20.0 / 800.0);
    EXPECT_DOUBLE_EQ(m.rmse, std::sqrt(20.0 / 800.0));
    EXPECT_DOUBLE_EQ(m.ssim, 1.0);  // luminance only, as docs/golden-tests.md defines it
    CompareThresholds t;
    t.max_abs = 0;
    EXPECT_EQ(failed_thresholds(m, t).size(), 1u);
}

TEST(CompareTest, ImagesWithoutAlphaCompareRgbAndChannelCountsMustAgree) {
    Image a = test_image(8, 8, 4);
    a.file_channels = 3;
    a.has_alpha = false;
    Image b = a;
    b.pixel(2, 2)[0] += 0.25f;
    CompareMetrics m = compare_ok(a, b);
    EXPECT_EQ(m.channels, 3);
    // One sample of 3 * 64 differs by 0.25 (the filler alpha counts nowhere).
    EXPECT_NEAR(m.mean_abs, 0.25 / 192.0, 1e-9);
    EXPECT_TRUE(m.channel_mismatch.empty());

    Image rgba = a;
    rgba.file_channels = 4;
    rgba.has_alpha = true;
    m = compare_ok(a, rgba);
    EXPECT_EQ(m.rmse, 0.0);
    EXPECT_NE(m.channel_mismatch.find("3"), std::string::npos) << m.channel_mismatch;
    EXPECT_NE(m.channel_mismatch.find("4"), std::string::npos) << m.channel_mismatch;
    // A failure whatever the thresholds, even generous ones.
    CompareThresholds t;
    t.max_rmse = 1;
    const auto failures = failed_thresholds(m, t);
    ASSERT_EQ(failures.size(), 1u);
    EXPECT_NE(failures[0].find("channel"), std::string::npos) << failures[0];
}

CompareMetrics compare_with(const Image& a, const Image& b, const CompareThresholds& t) {
    CompareMetrics m;
    std::string error;
    EXPECT_TRUE(compare_images(a, b, t, m, error)) << error;
    return m;
}

// A 10x10 grey image and a copy whose first 10 pixels (10%) are 0.2 brighter in red.
struct TenPercentPair {
    Image a{10, 10}, b;
    TenPercentPair() {
        for (size_t i = 0; i < a.rgba.size(); ++i) a.rgba[i] = 0.5f;
        b = a;
        for (int x = 0; x < 10; ++x) b.pixel(x, 0)[0] = 0.7f;
    }
};

TEST(CompareTest, NoThresholdFailsUnlessEveryValueAgreesTo1e6) {
    // Regression: unrelated images (RMSE ~0.2) passed when no threshold was given.
    const Image a = test_image(30, 20, 1), unrelated = test_image(30, 20, 2);
    const CompareThresholds none;
    EXPECT_FALSE(failed_thresholds(compare_with(a, unrelated, none), none).empty());
    EXPECT_TRUE(failed_thresholds(compare_with(a, a, none), none).empty());
    // 2^-21 ~ 4.8e-7 is within idiff's 1e-6; 2^-19 ~ 1.9e-6 is not (values near 0.5, where
    // float steps are 6e-8, so both offsets are exact).
    Image close = a, far = a;
    close.pixel(7, 7)[1] += std::ldexp(1.0f, -21);
    far.pixel(7, 7)[1] += std::ldexp(1.0f, -19);
    EXPECT_TRUE(failed_thresholds(compare_with(a, close, none), none).empty());
    EXPECT_EQ(failed_thresholds(compare_with(a, far, none), none).size(), 1u);
    // Any threshold of the user's replaces the default test.
    CompareThresholds rmse;
    rmse.max_rmse = 1;
    EXPECT_TRUE(failed_thresholds(compare_with(a, unrelated, rmse), rmse).empty());
}

TEST(CompareTest, IdiffFailFlags) {
    const TenPercentPair p;
    auto fails = [&](CompareThresholds t) {
        return !failed_thresholds(compare_with(p.a, p.b, t), t).empty();
    };
    CompareThresholds t;
    // float(0.7) - float(0.5) = 0.19999999 within float rounding; thresholds sit 0.05 either side.
    t.fail = 0.25;
    EXPECT_FALSE(fails(t));
    t.fail = 0.15;
    EXPECT_TRUE(fails(t));
    t = {};
    t.failpercent = 10;  // 10 of 100 pixels over the default 1e-6: not more than 10%
    EXPECT_FALSE(fails(t));
    t.failpercent = 9;
    EXPECT_TRUE(fails(t));
    t = {};
    t.failpercent = 100;
    t.hardfail = 0.25;
    EXPECT_FALSE(fails(t));
    t.hardfail = 0.15;
    EXPECT_TRUE(fails(t));
    // --hardfail alone keeps idiff's --fail 1e-6 --failpercent 0.
    t = {};
    t.hardfail = 1;
    EXPECT_TRUE(fails(t));
}

TEST(CompareTest, IdiffWarnFlagsWarnAndNeverFail) {
    const TenPercentPair p;
    auto warns = [&](CompareThresholds t) {
        t.failpercent = 100;  // the fail test passes, so only the warning test speaks
        const CompareMetrics m = compare_with(p.a, p.b, t);
        EXPECT_TRUE(failed_thresholds(m, t).empty());
        return !warned_thresholds(m, t).empty();
    };
    CompareThresholds t;
    EXPECT_FALSE(warns(t));  // no warning flag, no warning test
    t.warn = 0.25;
    EXPECT_FALSE(warns(t));
    t.warn = 0.15;
    EXPECT_TRUE(warns(t));
    t = {};
    t.warnpercent = 10;
    EXPECT_FALSE(warns(t));
    t.warnpercent = 9;
    EXPECT_TRUE(warns(t));
    t = {};
    t.warnpercent = 100;
    t.hardwarn = 0.25;
    EXPECT_FALSE(warns(t));
    t.hardwarn = 0.15;
    EXPECT_TRUE(warns(t));
}

TEST(CompareTest, NonFiniteValuesFailEverything) {
    Image a(12, 12);
    Image b = a;
    b.pixel(3, 3)[1] = std::numeric_limits<float>::quiet_NaN();
    const CompareMetrics m = compare_ok(a, b);
    EXPECT_TRUE(std::isinf(m.max_abs));
    EXPECT_DOUBLE_EQ(m.fail_percent, 100.0 / 144.0);
    CompareThresholds t;
    t.max_rmse = 1.0;
    t.min_ssim = 0.0;
    EXPECT_EQ(failed_thresholds(m, t).size(), 2u);
}

TEST(CompareTest, ThresholdsPassAndFail) {
    CompareMetrics m;
    m.rmse = 0.02;
    m.psnr = 33.98;
    m.mean_abs = 0.01;
    m.max_abs = 0.3;
    m.ssim = 0.97;
    m.fail_percent = 2.5;
    m.idiff_fail_percent = 4;

    // No threshold: idiff's default test (no pixel over 1e-6) fails alone.
    CompareThresholds none;
    const auto by_default = failed_thresholds(m, none);
    ASSERT_EQ(by_default.size(), 1u);
    EXPECT_NE(by_default[0].find("no threshold given"), std::string::npos) << by_default[0];

    CompareThresholds pass;
    pass.max_rmse = 0.02;  // equality passes
    pass.min_psnr = 30;
    pass.min_ssim = 0.97;
    pass.max_abs = 0.5;
    pass.max_fail_percent = 3;
    EXPECT_TRUE(failed_thresholds(m, pass).empty());

    CompareThresholds fail;
    fail.max_rmse = 0.01;
    fail.min_psnr = 40;
    fail.min_ssim = 0.99;
    fail.max_abs = 0.1;
    fail.max_fail_percent = 1;
    const auto failures = failed_thresholds(m, fail);
    ASSERT_EQ(failures.size(), 5u);
    EXPECT_NE(failures[0].find("RMSE"), std::string::npos);
    EXPECT_NE(failures[0].find("--max-rmse"), std::string::npos);
    EXPECT_NE(failures[1].find("PSNR"), std::string::npos);
    EXPECT_NE(failures[2].find("SSIM"), std::string::npos);
    EXPECT_NE(failures[3].find("--max-abs"), std::string::npos);
    EXPECT_NE(failures[4].find("--max-fail-percent"), std::string::npos);

    CompareThresholds only_psnr;
    only_psnr.min_psnr = 1000;
    m.psnr = std::numeric_limits<double>::infinity();  // identical images pass any PSNR minimum
    EXPECT_TRUE(failed_thresholds(m, only_psnr).empty());
}

TEST(CompareTest, JsonReportIsValidAtFullPrecision) {
    CompareMetrics m;
    m.rmse = 0.1234567890123456789;  // more digits than the old %g-style 6
    m.max_abs = 1.0 / 3.0;
    m.psnr = std::numeric_limits<double>::infinity();
    const std::string text = format_metrics_json(m, {"a \"quoted\" \\ line\n"}, {"ctrl \x01"});
    const nlohmann::json j = nlohmann::json::parse(text);
    EXPECT_EQ(j["rmse"].get<double>(), m.rmse);  // exact: a double round-trips
    EXPECT_EQ(j["max_abs"].get<double>(), 1.0 / 3.0);
    EXPECT_EQ(j["psnr"], "inf");
    EXPECT_EQ(j["failures"][0], "a \"quoted\" \\ line\n");
    EXPECT_EQ(j["warnings"][0], "ctrl \x01");
    EXPECT_EQ(j["pass"], false);
    EXPECT_EQ(j["channels"], 4);
}

TEST(CompareTest, JsonReport) {
    CompareMetrics m;
    m.width = 4;
    m.height = 3;
    m.rmse = 0.1;
    m.psnr = 20;
    m.ssim = 0.5;
    const nlohmann::json pass = nlohmann::json::parse(format_metrics_json(m, {}));
    EXPECT_EQ(pass["pass"], true);
    EXPECT_EQ(pass["rmse"].get<double>(), 0.1);
    EXPECT_EQ(pass["width"], 4);
    EXPECT_TRUE(pass["failures"].empty());
    const nlohmann::json fail = nlohmann::json::parse(format_metrics_json(m, {"say \"no\""}));
    EXPECT_EQ(fail["pass"], false);
    EXPECT_EQ(fail["failures"], nlohmann::json::array({"say \"no\""}));
    // The bench scripts read figures with grep '"rmse": NUMBER'.
    EXPECT_NE(format_metrics_json(m, {}).find("\"rmse\": 0.1"), std::string::npos);
}

TEST(CompareTest, TextReportIsAligned) {
    CompareMetrics m;
    m.width = 640;
    m.height = 480;
    m.rmse = 0.00123;
    m.psnr = 58.2;
    const std::string text = format_metrics_text(m);
    EXPECT_NE(text.find("640 x 480"), std::string::npos) << text;
    // Every value starts in the same column.
    size_t start = 0;
    int lines = 0;
    while (start < text.size()) {
        const size_t end = text.find('\n', start);
        ASSERT_NE(end, std::string::npos);
        const std::string line = text.substr(start, end - start);
        EXPECT_GE(line.size(), 16u) << line;
        EXPECT_EQ(line[14], ' ') << line;
        EXPECT_NE(line[15], ' ') << line;
        start = end + 1;
        ++lines;
    }
    EXPECT_EQ(lines, 8);
}

TEST(CompareTest, HeatmapRampAndSize) {
    Image a(5, 2), b(5, 2);
    const double diffs[5] = {0.0, 1e-3, 1e-2, 1e-1, 2.0};
    const float expected[5][3] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}};
    for (int x = 0; x < 5; ++x) b.pixel(x, 1)[2] = float(diffs[x]);
    const Image heat = difference_heatmap(a, b);
    ASSERT_EQ(heat.width, 5);
    ASSERT_EQ(heat.height, 2);
    for (int x = 0; x < 5; ++x) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(heat.pixel(x, 1)[c], expected[x][c], 1e-5) << x << " " << c;
            EXPECT_EQ(heat.pixel(x, 0)[c], 0.0f);
        }
        EXPECT_EQ(heat.pixel(x, 1)[3], 1.0f);
    }
    // Monotone brightness along the ramp.
    float prev = -1;
    for (double d = 1e-5; d < 2; d *= 1.3) {
        float rgb[3];
        heatmap_color(d, rgb);
        const float sum = rgb[0] + rgb[1] + rgb[2];
        EXPECT_GE(sum + 1e-6f, prev) << d;
        prev = sum;
    }
}

}  // namespace
}  // namespace vr
