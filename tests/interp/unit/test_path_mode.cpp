// G61 / G64 P / G09 (FEATURES PATH-1, PATH-2, PATH-3, PATH-9: accepted by NcStudio as an
// extension). Expected texts follow canon.hpp's contract; tolerances worked out by hand.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "block_builder.hpp"
#include "interp/canon_print.hpp"
#include "interp/executor.hpp"

namespace interp {
namespace {

struct Lines : CanonSink {
    std::vector<std::string> text;
    std::vector<Canon> all;
    void emit(const Canon& c) override {
        all.push_back(c);
        const std::string t = to_text(c.cmd);
        if (t.rfind("offsets ", 0) != 0) text.push_back(t);
    }
};

std::vector<std::string> run(const std::vector<std::string>& lines) {
    Lines out;
    Executor e(out, BackendConfig{});
    int n = 0;
    for (const auto& l : lines) e.execute(test::blk(l, ++n));
    return out.text;
}

std::string error_of(const std::vector<std::string>& lines) {
    Lines out;
    Executor e(out, BackendConfig{});
    int n = 0;
    try {
        for (const auto& l : lines) e.execute(test::blk(l, ++n));
    } catch (const Error& err) {
        return err.what();
    }
    return "no error";
}

using V = std::vector<std::string>;

TEST(PathMode, G61AndG64AreAnnouncedEachTimeTheyAreWritten) {
    EXPECT_EQ(run({"G61", "G01 X1 F60", "G61", "G64", "G64 P0.05"}),
              (V{"blending exact", "feed-rate 1mm/s", "feed X1 Y0 Z0", "blending exact",
                 "blending continuous tolerance=default",
                 "blending continuous tolerance=0.05mm"}));
}

TEST(PathMode, G64ToleranceIsInProgramUnits) {
    // 0.01 inch = 0.254 mm.
    EXPECT_EQ(run({"G20 G64 P0.01"}), (V{"units inch", "blending continuous tolerance=0.254mm"}));
}

TEST(PathMode, G64P0MeansTheMachineDefault) {
    EXPECT_EQ(run({"G64 P0"}), (V{"blending continuous tolerance=default"}));
}

TEST(PathMode, ModeAppliesBeforeTheMoveOfTheSameBlock) {
    EXPECT_EQ(run({"G61 G01 X2 F60"}), (V{"feed-rate 1mm/s", "blending exact", "feed X2 Y0 Z0"}));
}

TEST(PathMode, G09StopsOnlyItsOwnBlock) {
    EXPECT_EQ(run({"G09 G01 X1 F60", "X2", "G09 G00 Z1", "G9 G02 X4 R1"}),
              (V{"feed-rate 1mm/s", "feed X1 Y0 Z0 exact-stop", "feed X2 Y0 Z0",
                 "traverse X2 Y0 Z1 exact-stop", "arc XY turns=-1 X4 Y0 Z1 centre=(3 0 1) exact-stop"}));
}

TEST(PathMode, G61AndG64InOneBlockIsAnError) {
    EXPECT_EQ(error_of({"G61 G64"}), "test.nc:1:5: G61 and G64 are in the same modal group");
}

TEST(PathMode, NegativeToleranceIsAnError) {
    EXPECT_EQ(error_of({"G64 P-1"}), "test.nc:1:5: G64: negative blend tolerance P-1");
}

TEST(PathMode, PSharedWithAnotherCodeIsAnError) {
    EXPECT_EQ(error_of({"G04 G64 P100"}), "test.nc:1:9: G64 and G04 in one block: P is ambiguous");
    EXPECT_EQ(error_of({"G64 M802 P3"}), "test.nc:1:10: G64 and M802 in one block: P is ambiguous");
}

TEST(PathMode, ProgramEndRestoresContinuousOnlyWhenChanged) {
    Lines a;
    Executor e(a, BackendConfig{});
    e.execute(test::blk("G61", 1));
    e.execute(test::blk("M02", 2));
    EXPECT_EQ(a.text, (V{"blending exact", "blending continuous tolerance=default", "program-end"}));
    EXPECT_FALSE(e.state().path.exact);
    Lines b;
    Executor f(b, BackendConfig{});
    f.execute(test::blk("G01 X1 F60", 1));
    f.execute(test::blk("M30", 2));
    EXPECT_EQ(b.text, (V{"feed-rate 1mm/s", "feed X1 Y0 Z0", "program-end rewind"}));
}

TEST(PathMode, RejectedBlockKeepsTheMode) {
    Lines a;
    Executor e(a, BackendConfig{});
    e.execute(test::blk("G64 P0.2", 1));
    EXPECT_THROW(e.execute(test::blk("G61 G01 X1", 2)), Error);  // no feed yet
    EXPECT_FALSE(e.state().path.exact);
    EXPECT_DOUBLE_EQ(e.state().path.tolerance_mm, 0.2);
}

// The calls and numbers are those LinuxCNC 2.9's `rs274 -g` printed for
// "G20 / G64 P0.01 / G61 / G1 X1 F100 / G21 / G64 / G64 P0.1" on this machine.
TEST(PathMode, LinuxCncFormat) {
    std::FILE* f = std::tmpfile();
    {
        LinuxCncPrinter p(f);
        Executor e(p, BackendConfig{});
        int n = 0;
        for (const char* l : {"G20", "G64 P0.01", "G61", "G1 X1 F100", "G21", "G64", "G64 P0.1",
                              "G09 G1 X30"})
            e.execute(test::blk(l, ++n));
        p.finish();
    }
    std::rewind(f);
    std::string s;
    char buf[256];
    while (std::fgets(buf, sizeof buf, f)) s += buf;
    std::fclose(f);
    const std::string want =
        "    8 N..... SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.010000)\n"
        "    9 N..... SET_NAIVECAM_TOLERANCE(0.0100)\n"
        "   10 N..... SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)\n"
        "   11 N..... SET_FEED_RATE(100.0000)\n"
        "   12 N..... STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "   13 N..... USE_LENGTH_UNITS(CANON_UNITS_MM)\n"
        "   14 N..... SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.000000)\n"
        "   15 N..... SET_NAIVECAM_TOLERANCE(0.0000)\n"
        "   16 N..... SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.100000)\n"
        "   17 N..... SET_NAIVECAM_TOLERANCE(0.1000)\n"
        "   18 N..... STRAIGHT_FEED(30.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "   19 N..... COMMENT(\"native: exact-stop\")\n";
    EXPECT_NE(s.find(want), std::string::npos) << s;
}

}  // namespace
}  // namespace interp
