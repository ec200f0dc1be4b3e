// The batch render's command line (app/cli.h, app/commands.h): when a render is a batch, and how a
// --list line's options combine with the command line's.
#include <gtest/gtest.h>

#include <vector>

#include "app/cli.h"

namespace vr {
namespace {

int parse(std::vector<const char*> args, CommandLine& cmd) {
    args.insert(args.begin(), "vrmlray");
    return parse_command_line(int(args.size()), args.data(), cmd);
}

TEST(BatchCli, OneSceneToAFileIsNoBatch) {
    CommandLine cmd;
    ASSERT_EQ(parse({"render", "a.wrl", "-o", "a.png"}, cmd), -1);
    EXPECT_EQ(cmd.render.scene, "a.wrl");
    EXPECT_FALSE(is_batch(cmd.render));
}

TEST(BatchCli, SeveralScenesATrailingSlashOrAListAreBatches) {
    CommandLine many, slash, list;
    ASSERT_EQ(parse({"render", "a.wrl", "b.x3d", "-o", "out/"}, many), -1);
    EXPECT_EQ(many.render.scenes, (std::vector<std::string>{"a.wrl", "b.x3d"}));
    EXPECT_TRUE(is_batch(many.render));
    ASSERT_EQ(parse({"render", "a.wrl", "-o", "out/"}, slash), -1);
    EXPECT_TRUE(is_batch(slash.render));
    ASSERT_EQ(parse({"render", "--list", "suite.txt", "-W", "64", "-o", "out/"}, list), -1);
    EXPECT_TRUE(is_batch(list.render));
    // A --list line extends the words after "render".
    EXPECT_EQ(list.render.args,
              (std::vector<std::string>{"--list", "suite.txt", "-W", "64", "-o", "out/"}));
}

TEST(BatchCli, ASceneOrAListIsRequiredNotBoth) {
    CommandLine none, both;
    EXPECT_EQ(parse({"render", "-W", "10"}, none), kExitUsage);
    EXPECT_EQ(parse({"render", "a.wrl", "--list", "l.txt"}, both), kExitUsage);
}

TEST(BatchCli, AListLinesOptionsWinOverTheCommandLines) {
    RenderCommand render;
    ASSERT_EQ(
        parse_render_words({"-W", "64", "--spheres", "gas", "a.wrl", "--width", "20"}, render), -1);
    EXPECT_EQ(render.options.width, 20);
    EXPECT_EQ(render.options.spheres, SpheresOption::Gas);
    EXPECT_EQ(render.scene, "a.wrl");
}

TEST(BatchCli, TheCommandLineItselfStillRefusesAnOptionGivenTwice) {
    // Only a list line may repeat an option: on the command line a repeat is a typo to report.
    CommandLine cmd;
    EXPECT_EQ(parse({"render", "a.wrl", "-W", "64", "--width", "20"}, cmd), kExitUsage);
}

}  // namespace
}  // namespace vr
