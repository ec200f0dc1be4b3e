// Folder comparison (image/suite.h) and what it publishes (image/suite_report.h): pairing by
// relative path, statuses, worst-first order, the table, JUnit text and the report's files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "qa/suite.h"
#include "qa/suite_report.h"
#include "temp_path.h"

namespace vr {
namespace {
namespace fs = std::filesystem;

Image flat_image(int w, int h, float value) {
    Image image(w, h);
    for (size_t k = 0; k < image.rgba.size(); ++k) image.rgba[k] = (k % 4 == 3) ? 1.0f : value;
    return image;
}

void write_png(const fs::path& path, const Image& image) {
    fs::create_directories(path.parent_path());
    std::string error;
    ASSERT_TRUE(write_image(path.string(), image, false, error)) << error;
}

std::string read_text(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// A suite with one pair of each kind: same, changed by 10 codes, missing, extra, other size; and a
// text file beside the images, which is no image of the suite.
struct SuiteFolders : ::testing::Test {
    fs::path root = test::temp_path("vrmlray_suite_test");
    fs::path ref = root / "ref", out = root / "out";
    void SetUp() override {
        fs::remove_all(root);
        write_png(ref / "same.png", flat_image(8, 6, 0.5f));
        write_png(out / "same.png", flat_image(8, 6, 0.5f));
        write_png(ref / "sub/changed.png", flat_image(8, 6, 100.0f / 255));
        write_png(out / "sub/changed.png", flat_image(8, 6, 110.0f / 255));
        write_png(ref / "gone.png", flat_image(8, 6, 0.2f));
        write_png(out / "new.png", flat_image(8, 6, 0.2f));
        write_png(ref / "size.png", flat_image(8, 6, 0.2f));
        write_png(out / "size.png", flat_image(6, 8, 0.2f));
        std::ofstream(ref / "golden.txt") << "not an image\n";
    }
    void TearDown() override { fs::remove_all(root); }
};

const SuitePair& find(const std::vector<SuitePair>& pairs, const std::string& name) {
    for (const SuitePair& p : pairs)
        if (p.name == name) return p;
    static SuitePair none;
    ADD_FAILURE() << "no pair " << name;
    return none;
}

TEST_F(SuiteFolders, EachPairGetsItsStatusAndTextFilesAreNotImages) {
    const std::vector<SuitePair> pairs = compare_folders(ref, out, CompareThresholds{}, 2);
    ASSERT_EQ(pairs.size(), 5u);  // golden.txt is not one of them
    EXPECT_EQ(find(pairs, "same.png").status, PairStatus::kPass);
    EXPECT_EQ(find(pairs, "sub/changed.png").status, PairStatus::kFail);
    EXPECT_EQ(find(pairs, "gone.png").status, PairStatus::kMissing);
    EXPECT_EQ(find(pairs, "new.png").status, PairStatus::kExtra);
    EXPECT_EQ(find(pairs, "size.png").status, PairStatus::kSizeMismatch);
    EXPECT_NE(find(pairs, "size.png").message.find("8x6"), std::string::npos);
    // 10 8-bit codes on every colour sample (codes 100 and 110, exact in 8 bits): max abs 10/255,
    // to the float rounding of the PNG reader's code / 255.
    EXPECT_NEAR(find(pairs, "sub/changed.png").metrics.max_abs, 10.0 / 255, 1e-6);
}

TEST_F(SuiteFolders, AnUnreadableImageIsAnErrorOfItsOwnAndAJUnitError) {
    std::ofstream(ref / "broken.png") << "not a PNG";
    std::ofstream(out / "broken.png") << "not a PNG either";
    const std::vector<SuitePair> pairs = compare_folders(ref, out, CompareThresholds{}, 2);
    EXPECT_EQ(find(pairs, "broken.png").status, PairStatus::kUnreadable);
    EXPECT_FALSE(find(pairs, "broken.png").message.empty());
    const std::string x = format_junit(pairs, "suite");
    EXPECT_NE(x.find("tests=\"6\" failures=\"4\" errors=\"1\""), std::string::npos) << x;
    EXPECT_NE(x.find("<error type=\"error\""), std::string::npos);
}

TEST_F(SuiteFolders, WorstFirstStructuralFailuresThenThresholdsThenPasses) {
    const std::vector<SuitePair> pairs = compare_folders(ref, out, CompareThresholds{}, 2);
    for (size_t k = 1; k < pairs.size(); ++k)
        EXPECT_LE(int(pairs[k - 1].status), int(pairs[k].status)) << pairs[k].name;
    EXPECT_EQ(pairs.back().name, "same.png");
}

TEST_F(SuiteFolders, ThresholdsApplyToEveryPair) {
    CompareThresholds loose;
    loose.max_rmse = 0.05;  // above 10/255 = 0.039: the changed pair passes
    const std::vector<SuitePair> pairs = compare_folders(ref, out, loose, 1);
    EXPECT_EQ(find(pairs, "sub/changed.png").status, PairStatus::kPass);
    EXPECT_EQ(find(pairs, "size.png").status, PairStatus::kSizeMismatch);
}

TEST_F(SuiteFolders, APairsOwnThresholdsAreTheFirstMatchingRules) {
    SuiteThresholds thresholds;  // fallback: idiff's 1e-6, which the changed pair fails
    CompareThresholds loose, strict;
    loose.max_rmse = 0.05;  // above the changed pair's 10/255
    strict.max_rmse = 0.01;
    thresholds.rules = {{"sub/*.png", loose}, {"*changed*", strict}};  // the first wins
    const std::vector<SuitePair> pairs = compare_folders(ref, out, thresholds, 2);
    EXPECT_EQ(find(pairs, "sub/changed.png").status, PairStatus::kPass);
    EXPECT_EQ(&thresholds.for_pair("sub/changed.png"), &thresholds.rules[0].thresholds);
    EXPECT_EQ(&thresholds.for_pair("x/changed.png"), &thresholds.rules[1].thresholds);
    EXPECT_EQ(&thresholds.for_pair("same.png"), &thresholds.fallback);
}

TEST_F(SuiteFolders, TableHasALinePerPairWorstFirstAndTheCounts) {
    const std::string table = format_suite_table(compare_folders(ref, out, {}, 2));
    EXPECT_LT(table.find("missing"), table.find("sub/changed.png"));
    EXPECT_LT(table.find("sub/changed.png"), table.find("same.png"));
    EXPECT_NE(table.find("5 images: 1 passed, 0 warned, 4 failed"), std::string::npos) << table;
}

TEST_F(SuiteFolders, JUnitHasACasePerPairAndFailuresCarryTheFigures) {
    const std::string x = format_junit(compare_folders(ref, out, {}, 2), "a<b & \"c\"");
    EXPECT_NE(x.find("tests=\"5\" failures=\"4\" errors=\"0\""), std::string::npos) << x;
    EXPECT_NE(x.find("name=\"a&lt;b &amp; &quot;c&quot;\""), std::string::npos);  // escaped
    EXPECT_NE(x.find("<failure type=\"missing\""), std::string::npos);
    EXPECT_NE(x.find("<failure type=\"size\""), std::string::npos);
    // The threshold failure names the idiff test and gives the RMSE.
    const size_t changed = x.find("name=\"sub/changed.png\"");
    ASSERT_NE(changed, std::string::npos);
    const std::string rest = x.substr(changed, x.find("</testcase>", changed) - changed);
    EXPECT_NE(rest.find("<failure type=\"fail\""), std::string::npos) << rest;
    EXPECT_NE(rest.find("RMSE 0.039"), std::string::npos) << rest;
}

TEST_F(SuiteFolders, ReportWritesItsPagesImagesAndLegend) {
    const fs::path report = root / "report";
    std::string error;
    bool images_ok = true;
    const std::vector<SuitePair> pairs =
        compare_folders(ref, out, {}, 2, [&](const SuitePair& p, const Image& a, const Image& b) {
            std::string e;
            if (!write_report_images(report, p, a, b, e)) images_ok = false;
        });
    ASSERT_TRUE(images_ok);
    ASSERT_TRUE(write_report_html(report, pairs, "suite", error)) << error;
    EXPECT_TRUE(fs::exists(report / "ref/sub/changed.png.png"));
    EXPECT_TRUE(fs::exists(report / "out/sub/changed.png.png"));
    EXPECT_TRUE(fs::exists(report / "diff/sub/changed.png.png"));
    EXPECT_TRUE(fs::exists(report / "ref/gone.png.png"));    // a lone reference is still shown
    EXPECT_FALSE(fs::exists(report / "diff/size.png.png"));  // no heat-map across sizes
    const std::string html = read_text(report / "index.html");
    EXPECT_EQ(html.find("http"), std::string::npos);                   // nothing from the network
    EXPECT_LT(html.find("sub/changed.png"), html.find(">same.png<"));  // failures first
    EXPECT_NE(html.find("linear-gradient"), std::string::npos);        // the legend
}

}  // namespace
}  // namespace vr
