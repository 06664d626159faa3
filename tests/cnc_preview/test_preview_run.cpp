// `cnc run --preview` on the sim mill: the picture of examples/pocket.ngc. The expected sizes
// follow from the program: the path spans X 0..60, Y 0..50 (it starts at the machine origin),
// the pocket outline X 20..60, Y 20..50.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>

#include "preview_test_util.hpp"

namespace {

using namespace preview_test;
using cncrun::View;

using cnc_test::run_cnc;
using cnc_test::RunResult;

TEST(PreviewRun, PocketPngShowsTheOutlineInTheTopView) {
    ScratchDir dir;
    const fs::path png_path = dir.path() / "pocket.png";
    const RunResult r =
        run_cnc(fmt::format("configs/sim/mill.ini examples/pocket.ngc --sim-clock --preview '{}'",
                            png_path.string()),
                dir.path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("preview: " + png_path.string()), std::string::npos) << r.out;
    const Png png(png_path);
    ASSERT_EQ(png.status(), CAIRO_STATUS_SUCCESS);
    EXPECT_EQ(png.width(), cncrun::kPictureWidthPx);
    const auto plot = cncrun::plot_box(View::Top);
    const double px_per_mm = std::min(plot.w / 60, plot.h / 50);
    const PixelBounds blue = find_hue(png, cncrun::panel_box(View::Top), Hue::Blue);
    EXPECT_NEAR(blue.width(), 40 * px_per_mm, 3);
    EXPECT_NEAR(blue.height(), 30 * px_per_mm, 3);
    // The rapids: to the pocket's corner, and from it to X10 Y5 at the end.
    EXPECT_GT(find_hue(png, cncrun::panel_box(View::Top), Hue::Red).count, 0);
    for (View v : {View::Front, View::Side, View::Iso}) {
        EXPECT_GT(find_hue(png, cncrun::panel_box(v), Hue::Blue).count, 0);
        EXPECT_GT(find_hue(png, cncrun::panel_box(v), Hue::Red).count, 0);
    }
}

TEST(PreviewRun, OtherExtensionIsRefusedBeforeTheRun) {
    ScratchDir dir;
    const RunResult r = run_cnc(
        "configs/sim/mill.ini examples/pocket.ngc --sim-clock --preview pocket.gif", dir.path());
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.err.find("pocket.gif"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(".png or .svg"), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("motion time"), std::string::npos) << "it ran anyway";
}

}  // namespace
