// `simgrass render` in both kinds of build (replay/cli/render_hook.h): the command is always
// listed, and it is the offscreen renderer exactly when the viewer was built. Without the viewer,
// any invocation prints one line saying so and exits 2. This suite is in simgrass_tests, which
// builds either way; the renderer itself is tested in tests/render_test.cpp (viewer builds).
#include <gtest/gtest.h>

#include "tests/cli_support.h"

namespace sg {
namespace {

TEST(RenderHook, HelpListsTheRenderCommand) {
  const CliResult r = runCli("--help");
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_NE(r.out.find("\n  render "), std::string::npos) << r.out;
}

#if SIMGRASS_HAS_VIEWER
TEST(RenderHook, TheViewerBuildLinksTheOffscreenRenderer) {
  const CliResult r = runCli("render --help");
  ASSERT_EQ(r.exitCode, 0) << r.describe();
  EXPECT_NE(r.out.find("OSMesa"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--contact-sheet"), std::string::npos) << r.out;
}
#else
TEST(RenderHook, WithoutTheViewerRenderSaysSoInOneLine) {
  const std::string line = "simgrass render: this build has no viewer (configure with -DSIMGRASS_BUILD_VIEWER=ON)\n";
  for (const std::string args : {"render", "render scenarios/thesis-meadow.json -o frames --ticks 0:10 --size 64x48",
                                 "render whatever.sgr --no-such-option"}) {
    const CliResult r = runCli(args);
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.describe();
    EXPECT_TRUE(isOneLine(r.err)) << args;
    EXPECT_EQ(r.err, line) << args;
    EXPECT_TRUE(r.out.empty()) << args << "\n" << r.out;
  }
}
#endif

}  // namespace
}  // namespace sg
