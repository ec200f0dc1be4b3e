// The defaults docs/manual.md states and `vrmlray render --help` prints are the code's: each is
// read from the manual's option tables (the row of the option, its "default" column) and from the
// help text, and compared with RenderOptions{} and RenderCommand{}. A default changed in
// render/options.h without the manual fails here; --help is formatted from the values themselves.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "app/cli.h"
#include "core/format.h"
#include "render/sampling.h"

namespace vr {
namespace {

std::string manual_text() {
    std::ifstream in(std::string(VRMLRAY_SOURCE_DIR) + "/docs/manual.md");
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// The "default" column of the manual's table row whose first column is `option` exactly (as
// written in the manual, backquotes included); empty when there is no such row.
std::string manual_default(const std::string& manual, const std::string& option) {
    const std::string start = "\n| " + option + " | ";
    const size_t at = manual.find(start);
    if (at == std::string::npos) return "";
    const size_t begin = at + start.size();
    return manual.substr(begin, manual.find(" |", begin) - begin);
}

// The numbers in `text`, in order ("640 x 480" -> 640, 480; "2e-2" -> 0.02).
std::vector<double> numbers_in(const std::string& text) {
    static const std::regex number(R"([0-9]+(\.[0-9]+)?(e[-+]?[0-9]+)?)");
    std::vector<double> values;
    for (std::sregex_iterator it(text.begin(), text.end(), number), end; it != end; ++it)
        values.push_back(std::stod(it->str()));
    return values;
}

// The parsed command line of `vrmlray render s WORDS...`.
RenderCommand parsed(std::vector<std::string> words) {
    words.insert(words.begin(), {"vrmlray", "render", "s"});
    std::vector<const char*> argv;
    for (const std::string& w : words) argv.push_back(w.c_str());
    CommandLine cmd;
    EXPECT_EQ(parse_command_line(int(argv.size()), argv.data(), cmd), -1);
    return cmd.render;
}

TEST(ManualDefaults, NumbersInTheOptionTableAreTheCodes) {
    const std::string manual = manual_text();
    ASSERT_FALSE(manual.empty());
    const RenderOptions o;
    const RenderCommand c;
    const std::pair<const char*, std::vector<double>> rows[] = {
        {"`-W, --width`, `-H, --height`", {double(o.width), double(o.height)}},
        {"`--time T`", {c.time}},
        {"`--frames N`, `--fps F`", {double(c.frames), c.fps}},
        {"`--frames-at-once K`", {double(c.frames_at_once)}},
        {"`--adaptive-threshold T`, `--adaptive-depth D`",
         {o.adaptive_threshold, double(o.adaptive_depth)}},
        {"`--noise-threshold T`", {o.noise_threshold}},
        {"`--seed N`", {double(o.seed)}},
        {"`--max-depth N`", {double(o.max_depth)}},
        {"`--tolerance T`, `--density D`", {o.tolerance, o.density}},
        {"`--line-width PX`, `--point-size PX`", {o.line_width, o.point_size}},
        {"`--light-tolerance E`", {o.light_tolerance}},
        {"`--sky-share N`", {double(o.sky_share)}},
        {"`--outline [WIDTH][,R,G,B]`", {kDefaultOutlineWidth}},
        {"`--exposure EV`", {o.exposure}},
        {"`--light-scale S`", {o.light_scale}},
    };
    for (const auto& [option, values] : rows) {
        const std::string stated = manual_default(manual, option);
        ASSERT_FALSE(stated.empty()) << "docs/manual.md has no row " << option;
        const std::vector<double> numbers = numbers_in(stated);
        ASSERT_EQ(numbers.size(), values.size()) << option << ": \"" << stated << "\"";
        for (size_t k = 0; k < values.size(); ++k)
            EXPECT_DOUBLE_EQ(numbers[k], values[k]) << option << ": \"" << stated << "\"";
    }
    // The statistical sampler's cap, in the Samplers table.
    EXPECT_NE(manual.find("(default cap " + std::to_string(kDefaultStatisticalCap) + ")"),
              std::string::npos);
}

// A word the manual states as an enum option's default, given on the command line, sets the value
// RenderOptions{} starts with (so the manual, the command line's table and the code agree).
TEST(ManualDefaults, WordsInTheOptionTableAreTheCodes) {
    const std::string manual = manual_text();
    const RenderOptions o;
    const std::string sampler = manual_default(manual, "`--sampler NAME`, `--spp N`");
    EXPECT_EQ(sampler, std::string(sampler_name(o.sampler)) + ", " + std::to_string(o.spp));
    const std::string bvh = manual_default(manual, "`--bvh auto\\|sah\\|morton`");
    EXPECT_EQ(parsed({"--bvh", bvh}).options.bvh, o.bvh) << bvh;
    const std::string spheres = manual_default(manual, "`--spheres opaque\\|gas\\|hints`");
    EXPECT_EQ(parsed({"--spheres", spheres}).options.spheres, o.spheres) << spheres;
    const std::string camera = manual_default(manual, "`--camera perspective\\|ortho\\|viewpoint`");
    EXPECT_EQ(parsed({"--camera", camera}).options.camera, o.camera) << camera;
}

TEST(ManualDefaults, RenderHelpPrintsTheCodesDefaults) {
    const char* argv[] = {"vrmlray", "render", "--help"};
    CommandLine cmd;
    ::testing::internal::CaptureStdout();
    EXPECT_EQ(parse_command_line(3, argv, cmd), 0);
    const std::string help = ::testing::internal::GetCapturedStdout();
    const RenderOptions o;
    for (const std::string& said :
         {"(default: " + std::string(sampler_name(o.sampler)) + ", grid when --spp > 1)",
          "(default " + format_g(o.adaptive_threshold) + ")",
          "(default " + std::to_string(o.adaptive_depth) + ")",
          "(default " + format_g(o.noise_threshold) + ")",
          "the cap, default " + std::to_string(kDefaultStatisticalCap) + ")",
          "(default " + format_g(o.light_tolerance) + ")",
          "(default " + std::to_string(o.sky_share) + "; 1: every sample on its own)"})
        EXPECT_NE(help.find(said), std::string::npos) << "--help lacks " << said;
}

// PixelSampler starts from the same settings as RenderOptions.
TEST(ManualDefaults, ThePixelSamplerStartsFromTheOptionsDefaults) {
    const RenderOptions o;
    const PixelSampler s;
    EXPECT_EQ(s.adaptive_threshold, o.adaptive_threshold);
    EXPECT_EQ(s.adaptive_depth, o.adaptive_depth);
    EXPECT_EQ(s.noise_threshold, o.noise_threshold);
    EXPECT_EQ(s.max_samples, kDefaultStatisticalCap);
}

}  // namespace
}  // namespace vr
