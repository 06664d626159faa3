// Back-end unit tests with hand-built blocks. Every expected number below was worked out by hand
// from the manual's rule named in the test (FEATURES ids in the names).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "block_builder.hpp"
#include "interp/executor.hpp"

namespace interp {
namespace {

using test::blk;

struct Recorder : CanonSink {
    std::vector<Canon> all;
    void emit(const Canon& c) override { all.push_back(c); }
};

class ExecTest : public ::testing::Test {
  protected:
    void make(BackendConfig cfg = {}, Settings s = {}) {
        rec = Recorder{};
        exec = std::make_unique<Executor>(rec, cfg, s);
    }
    void SetUp() override { make(); }

    // Executes the lines and returns the text of the commands they produced, without the
    // offsets announcement the first block makes.
    std::vector<std::string> run(const std::vector<std::string>& lines) {
        const std::size_t from = rec.all.size();
        int n = 0;
        for (const auto& l : lines) exec->execute(blk(l, ++n));
        std::vector<std::string> out;
        for (std::size_t i = from; i < rec.all.size(); ++i) {
            std::string t = to_text(rec.all[i].cmd);
            if (t.rfind("offsets ", 0) == 0 && !keep_offsets) continue;
            out.push_back(t);
        }
        return out;
    }
    std::string error_of(const std::string& line) {
        try {
            exec->execute(blk(line, 7));
        } catch (const Error& e) {
            return e.what();
        }
        return "no error";
    }

    Recorder rec;
    std::unique_ptr<Executor> exec;
    bool keep_offsets = false;
};

using V = std::vector<std::string>;

TEST_F(ExecTest, G00_2_RapidSplitsZUpFirstAndZDownLast) {
    EXPECT_EQ(run({"G00 X10 Y20 Z5"}), (V{"traverse X0 Y0 Z5", "traverse X10 Y20 Z5"}));
    EXPECT_EQ(run({"G00 X30 Y40 Z-2"}), (V{"traverse X30 Y40 Z5", "traverse X30 Y40 Z-2"}));
    EXPECT_EQ(run({"G00 X0 Y0"}), (V{"traverse X0 Y0 Z-2"}));
    EXPECT_EQ(run({"G00 Z3"}), (V{"traverse X0 Y0 Z3"}));
}

TEST_F(ExecTest, G00_2_SplitCanBeSwitchedOff) {
    BackendConfig cfg;
    cfg.g00_z_split = false;
    make(cfg);
    EXPECT_EQ(run({"G00 X10 Y20 Z5"}), (V{"traverse X10 Y20 Z5"}));
}

TEST_F(ExecTest, G00_3_FInRapidBlockSetsRapidOnly) {
    // F600 mm/min = 10 mm/s. The first F also primes the cutting feed (REC).
    EXPECT_EQ(run({"G00 X1 F600"}),
              (V{"rapid-rate 10mm/s", "feed-rate 10mm/s", "traverse X1 Y0 Z0"}));
    EXPECT_EQ(run({"G00 X2 F1200"}), (V{"rapid-rate 20mm/s", "traverse X2 Y0 Z0"}));
    EXPECT_EQ(run({"G01 X3"}), (V{"feed X3 Y0 Z0"}));
    EXPECT_DOUBLE_EQ(exec->state().feed.feed_mm_s, 10.0);
    EXPECT_EQ(run({"G01 X4 F300"}), (V{"feed-rate 5mm/s", "feed X4 Y0 Z0"}));
}

// G00-4 / NCX-2: with "use default speed" on, moves run at the machine's default feed (here
// 1200 mm/min = 20 mm/s) and rapid speed (rapid-rate 0); F words only fill the programmed
// registers, which a G905 block runs at. The stream re-announces a rate when it changes.
TEST_F(ExecTest, G00_4_DefaultSpeedReplacesProgrammedF) {
    BackendConfig cfg;
    cfg.use_default_speed = true;
    cfg.default_feed_mm_s = 20;
    make(cfg);
    EXPECT_EQ(run({"G01 X1 F600"}), (V{"feed-rate 20mm/s", "feed X1 Y0 Z0"}));
    EXPECT_EQ(run({"G01 X2 F300"}), (V{"feed X2 Y0 Z0"}));
    // The manual's example: G905 G903 G01 … F600 runs at exactly 600 mm/min = 10 mm/s.
    EXPECT_EQ(run({"G905 G903 G01 X3 F600"}),
              (V{"feed-rate 10mm/s", "feed X3 Y0 Z0 override=100% programmed-feed"}));
    EXPECT_EQ(run({"G01 X4"}), (V{"feed-rate 20mm/s", "feed X4 Y0 Z0"}));
    // G905 without F in its block: the last programmed F (600).
    EXPECT_EQ(run({"G905 G02 X5 R0.5"}), (V{"feed-rate 10mm/s",
                                            "arc XY turns=-1 X5 Y0 Z0 "
                                            "centre=(4.5 0 0) programmed-feed"}));
    // F in a G00 block fills the programmed rapid register only (G00-3).
    EXPECT_EQ(run({"G00 X6 F3000"}), (V{"traverse X6 Y0 Z0"}));
    EXPECT_EQ(run({"G905 G00 X7"}), (V{"rapid-rate 50mm/s", "traverse X7 Y0 Z0 programmed-feed"}));
    EXPECT_EQ(run({"G00 X8"}), (V{"rapid-rate 0mm/s", "traverse X8 Y0 Z0"}));
    EXPECT_EQ(run({"G01 X9"}), (V{"feed-rate 20mm/s", "feed X9 Y0 Z0"}));
    EXPECT_DOUBLE_EQ(exec->state().feed.programmed.feed_mm_s, 10.0);
}

// G00-4 with canned cycles: the cycle's feed moves run at the default too, and a G905 cycle
// block at its own F (300 mm/min = 5 mm/s); every move of that block carries the flag.
TEST_F(ExecTest, G00_4_CannedCyclesRunAtTheDefaultFeed) {
    BackendConfig cfg;
    cfg.use_default_speed = true;
    cfg.default_feed_mm_s = 20;
    make(cfg);
    run({"G00 Z10"});
    EXPECT_EQ(run({"G81 X1 Y1 Z-5 R2 F300"}),
              (V{"feed-rate 20mm/s", "traverse X1 Y1 Z10", "traverse X1 Y1 Z2", "feed X1 Y1 Z-5",
                 "traverse X1 Y1 Z10"}));
    EXPECT_EQ(run({"G905 X2"}),
              (V{"feed-rate 5mm/s", "traverse X2 Y1 Z10 programmed-feed",
                 "traverse X2 Y1 Z2 programmed-feed", "feed X2 Y1 Z-5 programmed-feed",
                 "traverse X2 Y1 Z10 programmed-feed"}));
    EXPECT_EQ(run({"X3"}), (V{"feed-rate 20mm/s", "traverse X3 Y1 Z10", "traverse X3 Y1 Z2",
                              "feed X3 Y1 Z-5", "traverse X3 Y1 Z10"}));
}

TEST_F(ExecTest, G00_4_DefaultSpeedErrors) {
    BackendConfig cfg;
    cfg.use_default_speed = true;
    make(cfg);
    EXPECT_EQ(error_of("G01 X1 F600"),
              "test.nc:7:1: no default feed configured for a feed move (use default speed is on)");
    cfg.default_feed_mm_s = 20;
    make(cfg);
    EXPECT_EQ(error_of("G905 G01 X1"),
              "test.nc:7:1: G905: no feed rate programmed (F) for a feed move");
    EXPECT_EQ(run({"G905 G01 X1 F60"}), (V{"feed-rate 1mm/s", "feed X1 Y0 Z0 programmed-feed"}));
}

// LEX-51: dwell P is whole milliseconds (S0 §3.6.3 "不使用小数点"); a real fraction is rounded
// to the nearest millisecond with a warning (G04 and cycles), a trailing decimal point alone is
// not a fraction. By hand: round(1.5) = 2 ms, round(2.5) = 3 ms, round(0.4) = 0 ms.
TEST_F(ExecTest, LEX_51_DwellFractionsAreRoundedWithAWarning) {
    EXPECT_EQ(run({"G04 P1.5"}),
              (V{"warning \"G04 P1.5 is not whole milliseconds; rounded to P2\"", "dwell 0.002s"}));
    EXPECT_EQ(run({"G04 P0.4"}),
              (V{"warning \"G04 P0.4 is not whole milliseconds; rounded to P0\"", "dwell 0s"}));
    EXPECT_EQ(run({"G04 P1000."}), (V{"dwell 1s"}));
    run({"G00 Z10"});
    EXPECT_EQ(run({"G82 X1 Y1 Z-1 R1 P2.5 F60"}),
              (V{"feed-rate 1mm/s",
                 "warning \"canned-cycle P2.5 is not whole milliseconds; rounded to P3\"",
                 "traverse X1 Y1 Z10", "traverse X1 Y1 Z1", "feed X1 Y1 Z-1", "dwell 0.003s",
                 "traverse X1 Y1 Z10"}));
    // The rounded P is the cycle's modal dwell: the next hole dwells 3 ms too, unwarned.
    EXPECT_EQ(run({"X2"}), (V{"traverse X2 Y1 Z10", "traverse X2 Y1 Z1", "feed X2 Y1 Z-1",
                              "dwell 0.003s", "traverse X2 Y1 Z10"}));
}

TEST_F(ExecTest, FEED_8_FeedIsClampedWithOneWarningPerProgram) {
    BackendConfig cfg;
    cfg.max_feed_mm_s = 100;  // 6000 mm/min
    make(cfg);
    EXPECT_EQ(run({"G01 X1 F9000"}),
              (V{"warning \"F9000 exceeds the maximum feed 6000 mm/min; clamped\"",
                 "feed-rate 100mm/s", "feed X1 Y0 Z0"}));
    EXPECT_EQ(run({"X2 F12000"}), (V{"feed-rate 100mm/s", "feed X2 Y0 Z0"}));
    EXPECT_EQ(run({"X3 F600"}), (V{"feed-rate 10mm/s", "feed X3 Y0 Z0"}));
    run({"M30"});
    EXPECT_EQ(run({"G01 X1 F9000"}).front(),
              "warning \"F9000 exceeds the maximum feed 6000 mm/min; clamped\"");
}

TEST_F(ExecTest, G01_2_FeedMoveWithoutFeedIsAnError) {
    EXPECT_EQ(error_of("G01 X10"), "test.nc:7:1: no feed rate programmed (F) for a feed move");
}

TEST_F(ExecTest, ARC_EX08_QuarterArcByIJAndByRAreIdentical) {
    run({"G00 X10 Y20", "G01 F100"});
    // From (10,20) clockwise to (20,10) about (10,10).
    EXPECT_EQ(run({"G02 X20 Y10 I0 J-10"}), (V{"arc XY turns=-1 X20 Y10 Z0 centre=(10 10 0)"}));
    run({"G00 X10 Y20"});
    EXPECT_EQ(run({"G02 X20 Y10 R10"}), (V{"arc XY turns=-1 X20 Y10 Z0 centre=(10 10 0)"}));
    // 1(b): from (20,10) counter-clockwise to (10,20), same centre.
    EXPECT_EQ(run({"G03 X10 Y20 I-10 J0"}), (V{"arc XY turns=1 X10 Y20 Z0 centre=(10 10 0)"}));
}

TEST_F(ExecTest, ARC_EX08_FullCircleAndTwoHalfArcs) {
    run({"G01 F100"});
    EXPECT_EQ(run({"G02 X0 Y0 I20 J0"}), (V{"arc XY turns=-1 X0 Y0 Z0 centre=(20 0 0)"}));
    // R-20 from (0,0) to (20,-20): the long way round about (20,0) (radius 20, 270° CW).
    EXPECT_EQ(run({"G02 X20 Y-20 R-20"}), (V{"arc XY turns=-1 X20 Y-20 Z0 centre=(20 0 0)"}));
    EXPECT_EQ(run({"G02 X0 Y0 R20"}), (V{"arc XY turns=-1 X0 Y0 Z0 centre=(20 0 0)"}));
}

TEST_F(ExecTest, ARC_4_FullCircleWithROrNoCentreIsAnError) {
    run({"G01 F100"});
    EXPECT_EQ(error_of("G02 X0 Y0 R20"),
              "test.nc:7:1: a full circle cannot be programmed with R; use I/J/K");
    EXPECT_EQ(error_of("G02 X10 Y0"), "test.nc:7:1: arc needs R or I/J/K");
}

TEST_F(ExecTest, ARC_4_EndPointOmittedIsAFullCircle) {
    run({"G00 X20 Y0", "G01 F500"});
    EXPECT_EQ(run({"G03 I-20 J0"}), (V{"arc XY turns=1 X20 Y0 Z0 centre=(0 0 0)"}));
}

TEST_F(ExecTest, ARC_8_HelixAbsoluteAndIncrementalAgree) {
    run({"G00 X30 Y0", "G01 F300"});
    EXPECT_EQ(run({"G91 G17 G03 X-30 Y30 R30 Z10"}),
              (V{"plane XY", "arc XY turns=1 X0 Y30 Z10 centre=(0 0 0)"}));
    run({"G90 G00 X30 Y0 Z0"});
    EXPECT_EQ(run({"G90 G03 X0 Y30 R30 Z10"}), (V{"arc XY turns=1 X0 Y30 Z10 centre=(0 0 0)"}));
}

TEST_F(ExecTest, ARC_1_PlanesZXAndYZUseKIAndJK) {
    run({"G01 F100"});
    // G18: (first, second) = (Z, X). From (0,0,0) CW to X20 about X10 (I10).
    EXPECT_EQ(run({"G18 G02 X20 I10 K0"}),
              (V{"plane ZX", "arc ZX turns=-1 X20 Y0 Z0 centre=(10 0 0)"}));
    // G19: (Y, Z). From Y0 Z0 CCW to Y0 Z10 about Z5 (K5).
    EXPECT_EQ(run({"G19 G03 X20 Y0 Z10 J0 K5"}),
              (V{"plane YZ", "arc YZ turns=1 X20 Y0 Z10 centre=(20 0 5)"}));
}

TEST_F(ExecTest, ARC_11_EndPointOffTheCircleIsAnError) {
    run({"G01 F100"});
    EXPECT_EQ(error_of("G02 X20 Y1 I10 J0"),
              "test.nc:7:1: arc end point is not on the circle: radius 10 mm at the start, "
              "10.0499 mm at the end (difference 0.0499 mm, tolerance 0.01 mm)");
    // Within 0.01 mm is accepted.
    EXPECT_NO_THROW(exec->execute(blk("G02 X20.005 Y0 I10 J0")));
}

TEST_F(ExecTest, ARC_3_RadiusTooSmallIsAnErrorExceptInV54) {
    run({"G01 F100"});
    EXPECT_EQ(error_of("G02 X20 Y0 R5"),
              "test.nc:7:1: arc radius R5 is smaller than half the chord (10 mm)");
    BackendConfig cfg;
    cfg.v54_compat = true;
    make(cfg);
    run({"G01 F100"});
    EXPECT_EQ(run({"G02 X20 Y0 R5"}), (V{"arc XY turns=-1 X20 Y0 Z0 centre=(10 0 0)"}));
}

TEST_F(ExecTest, ARC_9_V54HelixLeadAddsTurns) {
    BackendConfig cfg;
    cfg.v54_compat = true;
    make(cfg);
    run({"G00 X30 Y0", "G01 F300"});
    // n = round(10/10 - 0.25) = 1 extra turn: a 450° sweep rising 10.
    EXPECT_EQ(run({"G90 G17 G03 X0 Y30 R30 Z10 K10"}),
              (V{"plane XY", "arc XY turns=2 X0 Y30 Z10 centre=(0 0 0)"}));
}

TEST_F(ExecTest, ARC_5_AbsoluteCentreSetting) {
    BackendConfig cfg;
    cfg.ijk_incremental = false;
    make(cfg);
    run({"G00 X10 Y20", "G01 F100"});
    EXPECT_EQ(run({"G02 X20 Y10 I10 J10"}), (V{"arc XY turns=-1 X20 Y10 Z0 centre=(10 10 0)"}));
}

TEST_F(ExecTest, ABS_2_G90AndG91InOneBlockIsAnError) {
    EXPECT_EQ(error_of("G90 G91 G00 X10"), "test.nc:7:5: G90 and G91 in the same block");
}

TEST_F(ExecTest, SameModalGroupIsAnError) {
    EXPECT_EQ(error_of("G00 G01 X10"), "test.nc:7:5: G00 and G01 are in the same modal group");
    EXPECT_EQ(error_of("M03 M05"), "test.nc:7:5: M03 and M05 are in the same modal group");
}

TEST_F(ExecTest, UnsupportedCodesAreNamed) {
    EXPECT_EQ(error_of("G00 G33 X1"), "test.nc:7:5: unsupported G code G33");
    EXPECT_EQ(error_of("G12.1"), "test.nc:7:1: unsupported G code G12.1");
    EXPECT_EQ(error_of("M19"), "test.nc:7:1: unsupported M code M19");
    // REF-8: S0 names G29 only among the codes forbidden under scaling; it is not provided.
    EXPECT_EQ(error_of("G29 X0"), "test.nc:7:1: unsupported G code G29");
}

TEST_F(ExecTest, TwoAxisUsersInOneBlockIsAnError) {
    EXPECT_EQ(error_of("G92 G51 X10 P2"), "test.nc:7:5: G92 and G51 both use the axis words");
}

// The messages of the setting-write, I/O and motion steps, each with the column of the word it
// names (a block's own column is 1). Every expected text was written from the rule it enforces.
TEST_F(ExecTest, ErrorMessagesOfSettingWrites) {
    EXPECT_EQ(error_of("G92"), "test.nc:7:1: G92 needs at least one axis word");
    EXPECT_EQ(error_of("G921"), "test.nc:7:1: G921 needs at least one axis word");
    EXPECT_EQ(error_of("G922 P0"), "test.nc:7:1: G922 needs at least one axis word");
    EXPECT_EQ(error_of("G923 P1"), "test.nc:7:1: G923 needs at least one of X Y Z");
    EXPECT_EQ(error_of("G992"), "test.nc:7:1: G992 needs X Y Z or I J K");
    EXPECT_EQ(error_of("G992 X1 I1"), "test.nc:7:1: G992: use either X Y Z or I J K, not both");
    EXPECT_EQ(error_of("G68 X0 Y0"), "test.nc:7:1: G68 needs R<angle in degrees>");
    EXPECT_EQ(error_of("G01 X1 F-5"), "test.nc:7:8: negative feed rate F-5");
    BackendConfig v54;
    v54.v54_compat = true;
    v54.t_changes_tool = false;
    make(v54);
    EXPECT_EQ(error_of("G992 I1"), "test.nc:7:1: G992 I J K is not available in NcStudio V5.4");
    EXPECT_EQ(error_of("M06"), "test.nc:7:1: M06 without a selected tool (T)");
}

TEST_F(ExecTest, ErrorMessagesOfMotionWords) {
    EXPECT_EQ(error_of("G53"), "test.nc:7:1: G53 needs axis words");
    EXPECT_EQ(error_of("G53 G02 X1 R1"), "test.nc:7:1: G53 works only with G00 or G01");
    EXPECT_EQ(error_of("G02 X1 R1 I1 F60"), "test.nc:7:8: arc has both R and I/J/K");
    run({"G64 P0.1 G01 X0 F60"});  // G64 P alone is fine
    run({"G81 X1 Y1 Z-1 R1"});
    EXPECT_EQ(error_of("G64 P0.1 X2"), "test.nc:7:5: G64 in a canned-cycle block: P is ambiguous");
}

TEST_F(ExecTest, ErrorMessagesOfTransforms) {
    // A 30° rotation in ZX tips the XY plane out of every machine plane.
    run({"G18 G68 X0 Z0 R30", "G17 G01 F60"});
    EXPECT_EQ(error_of("G02 X1 Y1 R1"),
              "test.nc:7:1: arc plane is not a machine plane after the programmed rotation");
    make();
    for (std::size_t i = 0; i < ProgramTransform::kMaxEntries; ++i) run({"G68 X0 Y0 R1"});
    EXPECT_EQ(error_of("G68 X0 Y0 R1"),
              "test.nc:7:1: G68: too many nested transforms (at most 32)");
}

TEST_F(ExecTest, ErrorMessagesOfMachineCodes) {
    Block msg = blk("G01 X1 F60", 7);
    msg.msg = "hello";
    EXPECT_THROW(
        {
            try {
                exec->execute(msg);
            } catch (const Error& e) {
                EXPECT_STREQ(e.what(), "test.nc:7:1: MSG is only allowed with M801");
                throw;
            }
        },
        Error);
    EXPECT_EQ(error_of("M802 P1.5"), "test.nc:7:6: M802: P must be an integer");
    EXPECT_EQ(error_of("M902"), "test.nc:7:1: M902 needs H<axis> (0=X 1=Y 2=Z 3=A)");
    auto kw_error = [&](Block b) {
        try {
            exec->execute(b);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    Block m901 = blk("M901", 7);
    m901.kw.plc = 4;
    EXPECT_EQ(kw_error(m901), "test.nc:7:1: M901 PLC[...] needs LEVEL0 or LEVEL1");
    m901.kw.level = 2;
    EXPECT_EQ(kw_error(m901), "test.nc:7:1: M901: LEVEL must be 0 or 1");
    Block g906 = blk("G906 P100", 7);
    g906.kw.plc = 4;
    g906.kw.level = 2;
    EXPECT_EQ(kw_error(g906), "test.nc:7:1: G906: LEVEL must be 0 or 1");
    g906 = blk("G906 P-1", 7);
    g906.kw.plc = 4;
    g906.kw.level = 1;
    EXPECT_EQ(kw_error(g906), "test.nc:7:6: G906: negative timeout");
    Block g916 = blk("G916", 7);
    g916.kw.p_axis[0] = 0;
    EXPECT_EQ(kw_error(g916), "test.nc:7:1: G916: axis X needs PX[addr] and LX");
    g916.kw.l_axis[0] = 3;
    EXPECT_EQ(kw_error(g916), "test.nc:7:1: G916: LX must be 0 or 1");
    Block g904 = blk("G904 Z-5", 7);
    EXPECT_EQ(kw_error(g904), "test.nc:7:6: G904: Z travel without FZ PZ LZ");
    g904 = blk("G904", 7);
    g904.kw.f_axis[2] = 0;
    g904.kw.p_axis[2] = 12;
    g904.kw.l_axis[2] = 1;
    EXPECT_EQ(kw_error(g904), "test.nc:7:1: G904: axis Z has speed 0");
    g904.kw.f_axis[2] = -60;
    g904.kw.l_axis[2] = 2;
    EXPECT_EQ(kw_error(g904), "test.nc:7:1: G904: LZ must be 0 or 1");
}

// S0's own CRC example starts with `G92 G0 X0 Y0`: the axis words belong to G92 and G00 only
// becomes the modal motion.
TEST_F(ExecTest, MotionCodeWithG92OnlySetsTheMode) {
    run({"G01 X5 F100"});
    EXPECT_EQ(run({"G92 G0 X0 Y0"}), (V{}));
    EXPECT_EQ(exec->state().motion.motion, Motion::Rapid);
    EXPECT_DOUBLE_EQ(exec->settings().offsets.g92[0], 5);
}

TEST_F(ExecTest, RejectedBlockChangesNothing) {
    run({"G00 X5 Y5", "G01 F100"});
    const ExecState before = exec->state();
    const std::size_t n = rec.all.size();
    // Units, feed, spindle and plane would change before the bad arc fails.
    EXPECT_NE(error_of("G20 G18 F50 S900 M03 G51 X0 P0"), "no error");
    EXPECT_NE(error_of("G20 S900 M03 G02 X20 Y1 I10 J0"), "no error");
    EXPECT_EQ(rec.all.size(), n);
    EXPECT_EQ(exec->state().units.mm_per_unit, before.units.mm_per_unit);
    EXPECT_EQ(exec->state().spindle.rpm, before.spindle.rpm);
    EXPECT_EQ(exec->state().spindle.dir, before.spindle.dir);
    EXPECT_EQ(exec->state().pos.machine_mm, before.pos.machine_mm);
    EXPECT_TRUE(exec->transform().identity());
}

TEST_F(ExecTest, UNIT_1_InchInputIsConvertedToMm) {
    EXPECT_EQ(run({"G20 G00 X1 Y2"}), (V{"units inch", "traverse X25.4 Y50.8 Z0"}));
    // After the first move a unit change still applies, with the C-37 warning.
    const std::string late =
        "warning \"G20/G21 after a move: units belong at the start of the program\"";
    EXPECT_EQ(run({"G70 G01 X2 F10"}),
              (V{late, "feed-rate 4.2333mm/s", "units inch", "feed X50.8 Y50.8 Z0"}));
    EXPECT_EQ(run({"G71 G00 X1"}), (V{late, "units mm", "traverse X1 Y50.8 Z0"}));
}

TEST_F(ExecTest, ABS_1_IncrementalMoves) {
    EXPECT_EQ(run({"G91 G00 X10", "X10 Y5"}), (V{"traverse X10 Y0 Z0", "traverse X20 Y5 Z0"}));
}

TEST_F(ExecTest, DW_1_DwellPInMilliseconds) {
    EXPECT_EQ(run({"G04 P1000"}), (V{"dwell 1s"}));
    EXPECT_EQ(run({"G04 P2500"}), (V{"dwell 2.5s"}));
    EXPECT_EQ(error_of("G04"), "test.nc:7:1: G04 needs P<milliseconds>");
    EXPECT_EQ(error_of("G04 P-5"), "test.nc:7:1: G04: negative dwell time");
}

TEST_F(ExecTest, WCS_1_WorkOffsetsSelectAndPersist) {
    Settings s;
    s.offsets.wcs[1] = {100, 50, -10, 0, 0, 0};
    make({}, s);
    keep_offsets = true;
    EXPECT_EQ(run({"G55"}), (V{"offsets G54 origin=(X0 Y0 Z0) shift=(X0 Y0 Z0)",
                               "offsets G55 origin=(X100 Y50 Z-10) shift=(X0 Y0 Z0)"}));
    keep_offsets = false;
    EXPECT_EQ(run({"G00 X1 Y1"}), (V{"traverse X101 Y51 Z0"}));
    // CS-3: a G54 switch does not move; the next move goes to G54 coordinates, and an axis that
    // is not written stays where the machine is.
    EXPECT_EQ(run({"G54", "G00 X1"}), (V{"traverse X1 Y51 Z0"}));
}

TEST_F(ExecTest, G92_2_ShiftMovesEveryWorkSystemAndPersists) {
    Settings s;
    s.offsets.wcs[1] = {100, 0, 0, 0, 0, 0};
    make({}, s);
    int saved = 0;
    exec->on_settings_changed([&](const Settings&) { ++saved; });
    run({"G00 X10 Y10", "G92 X0 Y0"});
    EXPECT_EQ(saved, 1);
    EXPECT_EQ(exec->settings().offsets.g92[0], 10);
    EXPECT_EQ(run({"G00 X5"}), (V{"traverse X15 Y10 Z0"}));
    EXPECT_EQ(run({"G55 G00 X5"}), (V{"traverse X115 Y10 Z0"}));
    EXPECT_DOUBLE_EQ(exec->work_pos_mm(Axis::X), 5);
    // Program end keeps it (G92-3).
    run({"M30"});
    EXPECT_EQ(exec->settings().offsets.g92[0], 10);
}

TEST_F(ExecTest, G921_1_SetsOnlyTheCurrentWorkSystem) {
    run({"G00 X10 Y10", "G921 X0"});
    EXPECT_EQ(exec->settings().offsets.wcs[0][0], 10);
    EXPECT_EQ(exec->settings().offsets.wcs[1][0], 0);
    EXPECT_EQ(exec->settings().offsets.g92[0], 0);
}

TEST_F(ExecTest, G922_1_WritesOriginsInMachineCoordinates) {
    run({"G922 X5 Y6 P1", "G922 Z-3 P-4", "G922 X7"});
    EXPECT_EQ(exec->settings().offsets.wcs[1][0], 5);
    EXPECT_EQ(exec->settings().offsets.wcs[1][1], 6);
    EXPECT_EQ(exec->settings().offsets.common[2], -3);
    EXPECT_EQ(exec->settings().offsets.wcs[0][0], 7);
    EXPECT_EQ(error_of("G922 X1 P6"),
              "test.nc:7:9: G922 offset type: P6 must be an integer in -4..5");
    EXPECT_EQ(error_of("G922 X1 P-2"), "test.nc:7:9: G922: P must be -4, -1 or 0..5");
}

TEST_F(ExecTest, G923_1_WritesToolOffsets) {
    run({"G923 Z2.392 P1", "T1", "G923 X0.5"});
    ASSERT_NE(exec->settings().tools.find(1), nullptr);
    EXPECT_DOUBLE_EQ(exec->settings().tools.find(1)->offset_mm[2], 2.392);
    EXPECT_DOUBLE_EQ(exec->settings().tools.find(1)->offset_mm[0], 0.5);
    make();
    EXPECT_EQ(error_of("G923 Z1"), "test.nc:7:1: G923: no current tool; give P<tool>");
}

TEST_F(ExecTest, G992_1_TemporarySystemIsRestoredAtProgramEnd) {
    run({"G00 X30 Y40", "G992 X0 Y0", "G00 X10"});
    EXPECT_DOUBLE_EQ(exec->state().pos.machine_mm[0], 40);
    // G992-2: I J K shift the temporary system.
    run({"G992 I5", "G00 X0 Y0"});
    EXPECT_DOUBLE_EQ(exec->state().pos.machine_mm[0], 35);
    EXPECT_DOUBLE_EQ(exec->state().pos.machine_mm[1], 40);
    EXPECT_EQ(error_of("G92 X0"),
              "test.nc:7:1: G92 is not allowed while a G992 temporary system is active");
    run({"M02"});
    EXPECT_EQ(exec->state().coord.g992_mm, AxisVec{});
    EXPECT_EQ(exec->settings().offsets, WorkOffsets{});
}

TEST_F(ExecTest, SCL_EX03_ScalingAboutACentre) {
    run({"G00 X50 Y50", "G51 X100 Y80 P0.5"});
    EXPECT_EQ(run({"G01 Y150 F1000", "X175 Y50", "G90 X50", "G50", "G00 X0 Y0"}),
              (V{"feed-rate 16.6667mm/s", "feed X75 Y115 Z0", "feed X137.5 Y65 Z0",
                 "feed X75 Y65 Z0", "traverse X0 Y0 Z0"}));
}

TEST_F(ExecTest, SCL_2_UnlistedAxesKeepTheirFactor) {
    run({"G51 X0 Y0 P2", "G51 Z0 P3", "G00 X1 Y1 Z1"});
    EXPECT_EQ(exec->state().pos.machine_mm, (AxisVec{2, 2, 3, 0, 0, 0}));
}

TEST_F(ExecTest, SCL_3_BadFactorsAreErrors) {
    EXPECT_EQ(error_of("G51 X0 P0"), "test.nc:7:8: G51: scale factor P is 0");
    EXPECT_EQ(error_of("G51 X0 P100"),
              "test.nc:7:8: G51: scale factor P100 outside 0.000001..99.999999");
    EXPECT_EQ(error_of("G51 X0 I0.0000005"),
              "test.nc:7:8: G51: scale factor I5e-07 outside 0.000001..99.999999");
    EXPECT_EQ(error_of("G51 X0 P-2"),
              "test.nc:7:8: G51: scale factor P-2 outside 0.000001..99.999999");
    EXPECT_EQ(error_of("G51 X0 P2 I2"), "test.nc:7:1: G51: use either P or I/J/K, not both");
    EXPECT_EQ(error_of("G51 X0"), "test.nc:7:1: G51 needs P<factor> or I/J/K factors");
    EXPECT_EQ(error_of("G51 P2"),
              "test.nc:7:1: G51 P scales the axes written in the block; none given");
}

// LEX-57: the bounds themselves are allowed (S0 §3.5.1 "0.000001-99.999999").
TEST_F(ExecTest, LEX_57_ScaleFactorBoundsAreAccepted) {
    run({"G51 X0 Y0 P99.999999", "G00 X1"});
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 99.999999, 1e-9);
    run({"G50", "G51 X0 Y0 P0.000001", "G00 X1000"});
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 0.001, 1e-12);
}

// LEX-57, SCL-4, MIR-6 (V5.4): P may also be -0.000001..-99.999999 (mirror and scale); 0 and
// anything outside both ranges is an alarm.
TEST_F(ExecTest, LEX_57_V54ScaleFactorRange) {
    BackendConfig cfg;
    cfg.v54_compat = true;
    make(cfg);
    EXPECT_EQ(error_of("G51 I0 J0 P0"), "test.nc:7:11: G51: scale factor P is 0");
    const std::string range =
        " outside 0.000001..99.999999 (negative: -0.000001..-99.999999, mirrors)";
    EXPECT_EQ(error_of("G51 I0 J0 P100"), "test.nc:7:11: G51: scale factor P100" + range);
    EXPECT_EQ(error_of("G51 I0 J0 P-100"), "test.nc:7:11: G51: scale factor P-100" + range);
    EXPECT_EQ(error_of("G51 I0 J0 P0.0000005"), "test.nc:7:11: G51: scale factor P5e-07" + range);
    EXPECT_EQ(error_of("G51 I0 J0 P-0.0000005"), "test.nc:7:11: G51: scale factor P-5e-07" + range);
    // The negative bound mirrors: X 10 -> -10 * 99.999999 about the centre 0. Z has no centre
    // word, so it keeps its factor 1 (S1 §3.3: omitted axes inherit the previous factor).
    run({"G51 I0 J0 P-99.999999", "G00 X10 Y0 Z-3"});
    EXPECT_NEAR(exec->state().pos.machine_mm[0], -999.99999, 1e-9);
    EXPECT_NEAR(exec->state().pos.machine_mm[2], -3, 1e-12);
}

TEST_F(ExecTest, SCL_1_PerAxisFactorsIJK) {
    run({"G51 X0 Y0 I0.666666 J3", "G00 X3 Y1"});
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 1.999998, 1e-9);
    EXPECT_NEAR(exec->state().pos.machine_mm[1], 3, 1e-9);
}

TEST_F(ExecTest, SCL_8_ForbiddenCodesWhileScaling) {
    run({"G51 X0 Y0 P2"});
    EXPECT_EQ(error_of("G28 X0"), "test.nc:7:1: G28 is not allowed while scaling (G51) is active");
    EXPECT_EQ(error_of("G53 G00 X0"),
              "test.nc:7:1: G53 is not allowed while scaling (G51) is active");
    EXPECT_EQ(error_of("G92 X0"), "test.nc:7:1: G92 is not allowed while scaling (G51) is active");
}

TEST_F(ExecTest, SCL_9_ScalingRotationMirrorEndWithTheProgram) {
    run({"G51 X0 Y0 P2", "G68 X0 Y0 R30", "G51.1 X0", "M30"});
    EXPECT_TRUE(exec->transform().identity());
}

TEST_F(ExecTest, ARC_15_NonUniformScalingOfArcIsAnError) {
    run({"G01 F100", "G51 X0 Y0 I1 J2"});
    EXPECT_EQ(error_of("G02 X20 Y0 I10 J0"),
              "test.nc:7:1: non-uniform scaling of arc (different G51 factors on the plane axes)");
}

TEST_F(ExecTest, ROT_EX04_RectangleRotatedMinus90) {
    run({"G01 F100", "G68 X0 Y0 R-90"});
    EXPECT_EQ(run({"G91 G01 X100", "Y50", "X-100", "Y-50", "G90"}),
              (V{"feed X0 Y-100 Z0", "feed X50 Y-100 Z0", "feed X50 Y0 Z0", "feed X0 Y0 Z0"}));
    run({"G69"});
    EXPECT_TRUE(exec->transform().identity());
}

TEST_F(ExecTest, ROT_3_NestedCentreIsInTheRotatedFrame) {
    // A: 90° about the origin. B: 90° about (10,0) written in A's frame, i.e. about (0,10).
    run({"G68 X0 Y0 R90", "G68 X10 Y0 R90", "G00 X10 Y0"});
    // Inner first: (10,0) about (10,0) stays (10,0); then A: (0,10).
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 0, 1e-9);
    EXPECT_NEAR(exec->state().pos.machine_mm[1], 10, 1e-9);
    run({"G00 X0 Y0"});
    // (0,0) about (10,0) by 90° -> (10,-10); then A -> (10,10).
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 10, 1e-9);
    EXPECT_NEAR(exec->state().pos.machine_mm[1], 10, 1e-9);
    // ROT-4: G69 pops B only; (0,0) under A alone stays (0,0), (10,0) -> (0,10).
    run({"G69", "G00 X10 Y0"});
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 0, 1e-9);
    EXPECT_NEAR(exec->state().pos.machine_mm[1], 10, 1e-9);
    EXPECT_EQ(exec->transform().size(), 1u);
}

TEST_F(ExecTest, ROT_2_RotationInZXKeepsY) {
    run({"G18 G68 X0 Z0 R90", "G00 Z10 Y3"});
    // In ZX (first Z, second X), +90° turns +Z into +X.
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 10, 1e-9);
    EXPECT_NEAR(exec->state().pos.machine_mm[1], 3, 1e-9);
    EXPECT_NEAR(exec->state().pos.machine_mm[2], 0, 1e-9);
}

TEST_F(ExecTest, MIR_1_MirrorLineAndArcDirectionFlip) {
    run({"G01 F100", "G51.1 X10", "G00 X0 Y0"});
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 20, 1e-9);
    // G02 about (10,0) prog -> machine centre (10,0), direction now CCW (ARC-14).
    EXPECT_EQ(run({"G02 X20 Y0 I10 J0"}), (V{"arc XY turns=1 X0 Y0 Z0 centre=(10 0 0)"}));
    run({"G50.1 X0", "G00 X1"});
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 1, 1e-9);
    EXPECT_EQ(error_of("G51.1"), "test.nc:7:1: G51.1 needs the mirror axes (X Y Z)");
}

TEST_F(ExecTest, MIR_1_MirrorThroughAPoint) {
    run({"G51.1 X10 Y10 Z10", "G00 X0 Y0 Z0"});
    EXPECT_EQ(exec->state().pos.machine_mm, (AxisVec{20, 20, 20, 0, 0, 0}));
}

// LEX-11: A B C are rotary axes in degrees; G20 converts only the linear words, G91 adds.
TEST_F(ExecTest, LEX_11_RotaryAxesABCInDegrees) {
    EXPECT_EQ(run({"G00 A90 B-45 C30"}), (V{"traverse X0 Y0 Z0 A90 B-45 C30"}));
    EXPECT_EQ(run({"G91 G00 A10 C-30", "G90"}), (V{"traverse X0 Y0 Z0 A100 B-45"}));
    make();
    run({"G20"});
    EXPECT_EQ(run({"G00 X1 A10"}), (V{"traverse X25.4 Y0 Z0 A10"}));
}

// LEX-50: calculator notation, a value without a decimal point is in whole units (mm, mm/min).
TEST_F(ExecTest, LEX_50_ValuesWithoutDecimalPointAreWholeUnits) {
    EXPECT_EQ(run({"G00 X50 Y20."}), (V{"traverse X50 Y20 Z0"}));
    EXPECT_EQ(run({"G01 X25 F600"}), (V{"feed-rate 10mm/s", "feed X25 Y20 Z0"}));
}

// PL-2: the plane selects arcs (and compensation), it does not restrict straight moves.
TEST_F(ExecTest, PL_2_PlaneDoesNotRestrictAxisMotion) {
    EXPECT_EQ(run({"G17 G00 Z5"}), (V{"plane XY", "traverse X0 Y0 Z5"}));
    EXPECT_EQ(run({"G18 G00 X1 Y2 Z4"}), (V{"plane ZX", "traverse X1 Y2 Z5", "traverse X1 Y2 Z4"}));
    EXPECT_EQ(run({"G19 G01 X3 Y4 Z6 F60"}), (V{"feed-rate 1mm/s", "plane YZ", "feed X3 Y4 Z6"}));
}

// SCL-6: scaling acts on the programmed contour only: work offsets and the tool length offset
// are added unscaled afterwards (S0 §3.5.1 "比例功能对补偿值无效").
TEST_F(ExecTest, SCL_6_ScalingLeavesOffsetsAndToolLengthAlone) {
    Settings s;
    s.offsets.wcs[0] = {100, 50, 0, 0, 0, 0};
    s.tools.at(1).offset_mm = {0, 0, 12.5};
    make({}, s);
    // (10,5,-1) scaled by 2 about the work origin = (20,10,-2); + G54 (100,50,0); + tool Z12.5.
    run({"G51 X0 Y0 Z0 P2", "G43 H1 G00 X10 Y5 Z-1"});
    EXPECT_EQ(exec->state().pos.machine_mm, (AxisVec{120, 60, 10.5, 0, 0, 0}));
}

// ROT-10 / MIR-4: a rotation programmed while one plane axis is mirrored turns the other way on
// the machine. Program (0,10) turned +90° is (-10,0); X mirrored about 0 gives (10,0), which is
// the mirror image of (0,10) — itself (0,10) — turned by -90°, clockwise.
TEST_F(ExecTest, ROT_10_OneMirroredAxisReversesTheRotation) {
    run({"G51.1 X0", "G68 X0 Y0 R90", "G00 X0 Y10"});
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 10, 1e-9);
    EXPECT_NEAR(exec->state().pos.machine_mm[1], 0, 1e-9);
    // Both plane axes mirrored is a half turn, not a reflection: the rotation keeps its sense.
    make();
    run({"G51.1 X0 Y0", "G68 X0 Y0 R90", "G00 X0 Y10"});
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 10, 1e-9);  // (-10,0) -> (10,0)
    EXPECT_NEAR(exec->state().pos.machine_mm[1], 0, 1e-9);
    run({"G00 X10 Y0"});  // (10,0) -> (0,10) -> (0,-10): the half-turned image of (10,0) +90°
    EXPECT_NEAR(exec->state().pos.machine_mm[0], 0, 1e-9);
    EXPECT_NEAR(exec->state().pos.machine_mm[1], -10, 1e-9);
}

TEST_F(ExecTest, TLC_EX11_LengthOffsetAddsToZ) {
    Settings s;
    s.tools.at(1).offset_mm = {0, 0, 12.5};
    make({}, s);
    run({"G90 G00 X5 Z0 F300"});
    EXPECT_EQ(run({"G43 G00 Z10 H01"}), (V{"tool-offset X0 Y0 Z12.5", "traverse X5 Y0 Z22.5"}));
    EXPECT_EQ(run({"G01 Z-10 F1000"}), (V{"feed-rate 16.6667mm/s", "feed X5 Y0 Z2.5"}));
    EXPECT_EQ(run({"G44 H1"}), (V{"tool-offset X0 Y0 Z-12.5"}));
    EXPECT_EQ(run({"G49"}), (V{"tool-offset X0 Y0 Z0"}));
    EXPECT_EQ(error_of("G43 H5"),
              "test.nc:7:5: tool length compensation: tool 5 is not in the tool table");
}

TEST_F(ExecTest, TLC_7_WithoutHTheCurrentToolIsUsed) {
    Settings s;
    s.tools.at(2).offset_mm = {0, 0, 7};
    make({}, s);
    EXPECT_EQ(run({"G43", "T2"}),
              (V{"tool-offset X0 Y0 Z0", "tool-change T2", "tool-offset X0 Y0 Z7"}));
}

TEST_F(ExecTest, M03_1_SpindleSpeedIsKeptWhileStopped) {
    EXPECT_EQ(run({"S500 M03", "M05", "M04"}),
              (V{"spindle-speed 500rpm", "spindle cw", "spindle stop", "spindle ccw"}));
    EXPECT_DOUBLE_EQ(exec->spindle_rpm(), 500);
    EXPECT_EQ(error_of("S-5"), "test.nc:7:1: negative spindle speed S-5");
}

TEST_F(ExecTest, M08_1_Coolant) {
    EXPECT_EQ(run({"M08", "M09"}), (V{"coolant on", "coolant off"}));
}

TEST_F(ExecTest, M10_1_ClampIsAWarningIn6thAndACommandInV54) {
    EXPECT_EQ(run({"M10"}),
              (V{"warning \"M10 is an invalid instruction in NcStudio 6th edition; ignored\""}));
    BackendConfig cfg;
    cfg.v54_compat = true;
    make(cfg);
    EXPECT_EQ(run({"M10", "M11"}), (V{"spindle-clamp on", "spindle-clamp off"}));
}

TEST_F(ExecTest, M06_1_TChangesToolAndM06FollowsV54) {
    EXPECT_EQ(run({"T3 M06"}), (V{"tool-change T3"}));
    BackendConfig cfg;
    cfg.t_changes_tool = false;
    make(cfg);
    EXPECT_EQ(run({"T4", "M06"}), (V{"tool-change T4"}));
}

TEST_F(ExecTest, M903_1_ChangesTheToolNumberOnly) {
    EXPECT_EQ(run({"M903 T5"}), (V{"tool-number T5"}));
    EXPECT_EQ(run({"M903 P6"}), (V{"tool-number T6"}));
    EXPECT_EQ(error_of("M903"), "test.nc:7:1: M903 needs T<tool> (or P<tool>)");
}

TEST_F(ExecTest, M01_1_OptionalStopFollowsTheSwitch) {
    EXPECT_EQ(run({"M00", "M01"}), (V{"stop"}));
    BackendConfig cfg;
    cfg.optional_stop = true;
    make(cfg);
    EXPECT_EQ(run({"M01"}), (V{"optional-stop"}));
}

TEST_F(ExecTest, M30_1_EndResetsModalStateAndStopsSpindle) {
    run({"G91 G20 G18 S100 M03 M08"});
    keep_offsets = true;
    EXPECT_EQ(run({"M30"}),
              (V{"spindle stop", "coolant off", "offsets G54 origin=(X0 Y0 Z0) shift=(X0 Y0 Z0)",
                 "program-end rewind"}));
    EXPECT_FALSE(exec->state().motion.incremental);
    EXPECT_EQ(exec->state().units.mm_per_unit, 1.0);
    EXPECT_EQ(exec->state().motion.plane, Plane::XY);
    EXPECT_EQ(run({"M02"}).back(), "program-end");
}

// M30-1 / END-1: ENABLE_CTP sends a normal end (M02, M30, end of input) to the fixed point
// CTP_POS in machine coordinates, after the automatic spindle stop; AUTOSTOPSPINDLE=0 keeps the
// spindle running. From (10,10,-5) to (-20,300,40): Z rises, so Z first.
TEST_F(ExecTest, M30_1_EnableCtpGoesToTheFixedPointAtTheEnd) {
    BackendConfig cfg;
    cfg.machine_settings = {
        {"ENABLE_CTP", 1}, {"CTP_POS.X", -20}, {"CTP_POS.Y", 300}, {"CTP_POS.Z", 40}};
    make(cfg);
    run({"G00 X10 Y10 Z-5 S100 M03"});
    EXPECT_EQ(run({"M30"}), (V{"spindle stop", "traverse X10 Y10 Z40", "traverse X-20 Y300 Z40",
                               "program-end rewind"}));
    cfg.machine_settings = {{"AUTOSTOPSPINDLE", 0}};
    make(cfg);
    run({"S100 M03"});
    EXPECT_EQ(run({"M02"}), (V{"program-end"}));
    EXPECT_EQ(exec->state().spindle.dir, SpindleDir::Cw);
}

// TLC-6 REC (and END-1): length compensation is cancelled at program end.
TEST_F(ExecTest, TLC_6_LengthCompEndsWithTheProgram) {
    Settings s;
    s.tools.at(1).offset_mm = {0, 0, 12.5};
    make({}, s);
    run({"G43 H1"});
    EXPECT_EQ(run({"M30"}), (V{"tool-offset X0 Y0 Z0", "program-end rewind"}));
    EXPECT_EQ(exec->state().tool.length_mode, ToolLengthMode::Off);
}

TEST_F(ExecTest, REF_2_G28ThroughIntermediatePoint) {
    BackendConfig cfg;
    cfg.reference_mm = {0, 0, 50, 0, 0, 0};
    make(cfg);
    run({"G00 X10 Y10 Z5"});
    // Intermediate (20, -, 10): Z rises first; then Z to the reference 50 alone with X to 0.
    EXPECT_EQ(run({"G28 X20 Z10"}), (V{"traverse X10 Y10 Z10", "traverse X20 Y10 Z10",
                                       "traverse X20 Y10 Z50", "traverse X0 Y10 Z50"}));
    EXPECT_EQ(error_of("G28"), "test.nc:7:1: G28 needs the axes to return (X Y Z)");
}

TEST_F(ExecTest, MCS_1_G53MovesInMachineCoordinates) {
    Settings s;
    s.offsets.wcs[0] = {100, 100, 0, 0, 0, 0};
    make({}, s);
    EXPECT_EQ(run({"G53 G00 X5 Y6"}), (V{"traverse X5 Y6 Z0"}));
    // Non-modal: the next move is in G54 again.
    EXPECT_EQ(run({"G00 X0"}), (V{"traverse X100 Y6 Z0"}));
    EXPECT_EQ(error_of("G91 G53 G00 X1"), "test.nc:7:5: G53 needs absolute coordinates (G90)");
}

// MCS-3 REC (NC default): G53 ignores the work offsets but keeps tool length compensation.
TEST_F(ExecTest, MCS_3_LengthCompStaysActiveUnderG53) {
    Settings s;
    s.offsets.wcs[0] = {100, 100, 50, 0, 0, 0};
    s.tools.at(1).offset_mm = {0, 0, 12.5};
    make({}, s);
    run({"G43 H1"});
    EXPECT_EQ(run({"G53 G00 X5 Y6 Z-20"}), (V{"traverse X5 Y6 Z0", "traverse X5 Y6 Z-7.5"}));
}

// UNIT-4 / END-3 REC: NcStudio starts metric; G21/G71 are the metric codes, G20/G70 inch.
TEST_F(ExecTest, UNIT_4_MetricIsTheDefault) {
    EXPECT_DOUBLE_EQ(exec->state().units.mm_per_unit, 1.0);
    EXPECT_EQ(run({"G00 X2"}), (V{"traverse X2 Y0 Z0"}));
}

TEST_F(ExecTest, M801_M802_Messages) {
    Block b = blk("M801");
    b.msg = "Hello";
    exec->execute(b);
    EXPECT_EQ(to_text(rec.all.back().cmd), "message \"Hello\"");
    EXPECT_EQ(run({"M802 P196609"}), (V{"int-message 196609"}));
    EXPECT_EQ(error_of("M801"), "test.nc:7:1: M801 needs MSG \"text\"");
    EXPECT_EQ(error_of("M802"), "test.nc:7:1: M802 needs P<integer message>");
}

TEST_F(ExecTest, M901_1_BothOutputForms) {
    Block b = blk("M901");
    b.kw.plc = 4;
    b.kw.level = 1;
    exec->execute(b);
    EXPECT_EQ(to_text(rec.all.back().cmd), "set-output PLC4 1");
    EXPECT_EQ(run({"M901 H2 P1", "M901 H24 P0"}), (V{"set-output H2 1", "set-output H24 0"}));
    EXPECT_EQ(exec->output_bits(), (1u << 2) | (1u << 4));
    EXPECT_EQ(error_of("M901 H2"),
              "test.nc:7:1: M901 needs PLC[addr] LEVEL<0|1> or H<port> P<0|1>");
}

TEST_F(ExecTest, M902_1_HomingSetsTheMachineCoordinate) {
    BackendConfig cfg;
    cfg.home_position_mm = {-5, 0, 0, 0, 0, 0};
    make(cfg);
    run({"G00 X30"});
    EXPECT_EQ(run({"M902 H0"}), (V{"home-done X at=-5"}));
    EXPECT_DOUBLE_EQ(exec->machine_pos_mm(Axis::X), -5);
    EXPECT_EQ(error_of("M902 H4"), "test.nc:7:6: M902 axis: H4 must be an integer in 0..3");
}

TEST_F(ExecTest, C31_M902InV54SetsZero) {
    BackendConfig cfg;
    cfg.v54_compat = true;
    cfg.home_position_mm = {-5, 0, 0, 0, 0, 0};  // ignored in V5.4: the point becomes 0
    make(cfg);
    run({"G00 X30"});
    EXPECT_EQ(run({"M902 H0"}), (V{"home-done X at=0"}));
    EXPECT_DOUBLE_EQ(exec->machine_pos_mm(Axis::X), 0);
}

TEST_F(ExecTest, FM_3_G94IsAcceptedAsFeedPerMinute) {
    EXPECT_EQ(run({"G94 G01 X1 F60"}),
              (V{"feed-mode per-minute", "feed-rate 1mm/s", "feed X1 Y0 Z0"}));
    EXPECT_EQ(error_of("G93 G01 X2"), "test.nc:7:1: unsupported G code G93");
    EXPECT_EQ(error_of("G95 G01 X2"), "test.nc:7:1: unsupported G code G95");
}

TEST_F(ExecTest, NCX_3_G904ConditionalMove) {
    Block b = blk("G904");
    b.kw.f_axis[2] = -60;
    b.kw.p_axis[2] = 12;
    b.kw.l_axis[2] = 1;
    exec->execute(b);
    EXPECT_EQ(to_text(rec.all.back().cmd), "conditional-move Z:speed=-1mm/s,input=12,level=1");
    Block bad = blk("G904", 7);
    bad.kw.f_axis[0] = 100;
    EXPECT_THROW(
        {
            try {
                exec->execute(bad);
            } catch (const Error& e) {
                EXPECT_STREQ(e.what(), "test.nc:7:1: G904: axis X needs FX, PX and LX");
                throw;
            }
        },
        Error);
    EXPECT_EQ(error_of("G904"), "test.nc:7:1: G904 needs at least one axis (FX PX LX …)");
}

TEST_F(ExecTest, NCX_4_G904V54Form) {
    BackendConfig cfg;
    cfg.v54_compat = true;
    make(cfg);
    EXPECT_EQ(run({"G904 Z-120 K3 H0"}), (V{"conditional-move Z:speed=-2mm/s,input=3,level=0"}));
}

TEST_F(ExecTest, NCX_5_6_G906SyncAndWait) {
    EXPECT_EQ(run({"G906"}), (V{"sync"}));
    Block b = blk("G906 P1000");
    b.kw.plc = 4;
    b.kw.level = 1;
    exec->execute(b);
    EXPECT_EQ(to_text(rec.all.back().cmd), "wait-input PLC4 level=1 timeout=1s");
    EXPECT_EQ(error_of("G906 P1000"),
              "test.nc:7:1: G906 with a port needs PLC[addr] LEVEL<0|1> P<timeout ms>");
}

TEST_F(ExecTest, NCX_9_10_11_Latch) {
    Block b = blk("G916");
    b.kw.p_axis[0] = 0;
    b.kw.l_axis[0] = 0;
    exec->execute(b);
    EXPECT_EQ(to_text(rec.all.back().cmd), "latch-config X input=0 level=0");
    EXPECT_EQ(run({"G918", "G919 H0"}), (V{"latch-clear", "latch-stop-distance X"}));
    EXPECT_EQ(error_of("G916"), "test.nc:7:1: G916 needs PX[addr] LX<0|1> (or Y/Z)");
    EXPECT_EQ(error_of("G919"), "test.nc:7:1: G919 needs H<axis> (0=X 1=Y 2=Z)");
}

TEST_F(ExecTest, NCX_1_2_7_8_MoveFlags) {
    EXPECT_EQ(run({"G905 G903 G01 X10 Y20 Z0 F600"}),
              (V{"feed-rate 10mm/s", "feed X10 Y20 Z0 override=100% programmed-feed"}));
    EXPECT_EQ(run({"G907 G908 G00 A90"}),
              (V{"traverse X10 Y20 Z0 A90 rotary-shortest rotary-degrees"}));
    // Non-modal.
    EXPECT_EQ(run({"G01 X0"}), (V{"feed X0 Y20 Z0 A90"}));
}

TEST_F(ExecTest, CS_2_MachineQueryAnswersFromTheModel) {
    Settings s;
    s.offsets.wcs[0] = {10, 20, 30, 0, 0, 0};
    s.params["MOBICALI_THICKNESS"] = 12;
    BackendConfig cfg;
    cfg.machine_settings["SAFEHEIGHT"] = 40;
    make(cfg, s);
    run({"G20 G00 X1 Y2 Z3"});
    EXPECT_NEAR(exec->machine_pos_mm(Axis::X), 35.4, 1e-9);
    EXPECT_NEAR(exec->work_pos_mm(Axis::Z), 76.2, 1e-9);
    EXPECT_DOUBLE_EQ(exec->mm_per_program_unit(), 25.4);
    EXPECT_EQ(exec->setting("MOBICALI_THICKNESS"), 12.0);
    EXPECT_EQ(exec->setting("SAFEHEIGHT"), 40.0);
    EXPECT_EQ(exec->setting("NOPE"), std::nullopt);
}

TEST_F(ExecTest, EndOfInputEndsTheProgram) {
    run({"G51 X0 Y0 P2"});
    exec->end_of_input(SourceLoc{"test.nc", 9, 1});
    EXPECT_EQ(to_text(rec.all.back()), "9 program-end");
    EXPECT_TRUE(exec->transform().identity());
}

}  // namespace
}  // namespace interp

namespace interp {
namespace {

TEST(ExecG904Sim, TriggerStopsTheAxisAndBadTriggersAreAlarms) {
    struct Null : CanonSink {
        void emit(const Canon&) override {}
    } sink;
    BackendConfig cfg;
    cfg.g904_trip_mm[2] = -5;
    Executor exec(sink, cfg);
    auto g904 = [&](double speed, std::optional<double> max_mm) {
        Block b = test::blk(max_mm ? "G904 Z" + std::to_string(*max_mm) : "G904", 4);
        b.kw.f_axis[2] = speed;
        b.kw.p_axis[2] = 1;
        b.kw.l_axis[2] = 1;
        try {
            exec.execute(b);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("ok");
    };
    EXPECT_EQ(g904(60, std::nullopt),
              "test.nc:4:1: G904: Z moves away from where its input changes (-5 mm)");
    EXPECT_EQ(g904(-60, 2.0), "test.nc:4:1: G904: Z travelled 2 mm without the input changing");
    EXPECT_EQ(g904(-60, 10.0), "ok");
    EXPECT_DOUBLE_EQ(exec.machine_pos_mm(Axis::Z), -5);
    EXPECT_DOUBLE_EQ(exec.work_pos_mm(Axis::Z), -5);
}

}  // namespace
}  // namespace interp

namespace interp {
namespace {

TEST(ExecCycles, GroupRulesAndReturnMode) {
    struct Null : CanonSink {
        void emit(const Canon&) override {}
    } sink;
    Executor exec(sink, BackendConfig{});
    auto err = [&](const std::string& line) {
        try {
            exec.execute(test::blk(line, 3));
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("ok");
    };
    EXPECT_EQ(err("G01 G81 X1 Z-1 R1 F100"), "test.nc:3:5: G01 and G81 cannot share a block");
    EXPECT_EQ(err("G92 G81 X1 Z-1 R1"), "test.nc:3:5: G92 and G81 both use the axis words");
    EXPECT_FALSE(exec.cycle_return_to_r());
    EXPECT_EQ(err("G99"), "ok");
    EXPECT_TRUE(exec.cycle_return_to_r());
    EXPECT_EQ(err("G40"), "ok");  // compensation is never on here, so cancelling is a no-op
    EXPECT_EQ(err("G41 D1"),
              "test.nc:3:5: cutter radius compensation: tool 1 is not in the tool table");
    // A group-01 code ends the cycle: the next X-only block is a plain move, not a hole.
    EXPECT_EQ(err("G81 X1 Z-1 R1 F60"), "ok");
    EXPECT_EQ(err("G00 X2"), "ok");
    EXPECT_EQ(err("X3"), "ok");
    EXPECT_DOUBLE_EQ(exec.machine_pos_mm(Axis::Z), 1);  // R level of the G81 hole (G99)
}

}  // namespace
}  // namespace interp

namespace interp {
namespace {

struct Lines : CanonSink {
    std::vector<std::string> text;
    void emit(const Canon& c) override {
        std::string t = to_text(c.cmd);
        if (t.rfind("offsets", 0) != 0) text.push_back(t);
    }
};

Settings radius5_tool() {
    Settings s;
    s.tools.at(1).diameter_mm = 10;
    return s;
}

std::string run_err(Executor& e, const std::string& line) {
    try {
        e.execute(test::blk(line, 5));
    } catch (const Error& err) {
        return err.what();
    }
    return "ok";
}

TEST(ExecCrc, LeftOfTravelAndMirroringSwapsTheSide) {
    Lines plain, mirrored;
    Executor a(plain, BackendConfig{}, radius5_tool());
    Executor b(mirrored, BackendConfig{}, radius5_tool());
    for (auto* e : {&a, &b}) {
        if (e == &b) e->execute(test::blk("G51.1 Y0"));
        for (const char* l : {"G41 G01 X10 Y0 D1 F600", "X20", "G40 X30"}) e->execute(test::blk(l));
        e->end_of_input(SourceLoc{"test.nc", 9, 1});
    }
    // Left of +X is +Y, so the compensated program path is at Y5. Mirroring Y must give the
    // mirror image of that path, Y−5: the compensator sees G42 (CRC-13).
    EXPECT_EQ(plain.text[1], "feed X10 Y5 Z0");
    EXPECT_EQ(plain.text[2], "feed X20 Y5 Z0");
    EXPECT_EQ(mirrored.text[1], "feed X10 Y-5 Z0");
    EXPECT_EQ(mirrored.text[2], "feed X20 Y-5 Z0");
}

TEST(ExecCrc, ForbiddenCodesAndDAlone) {
    Lines out;
    Executor e(out, BackendConfig{}, radius5_tool());
    EXPECT_EQ(run_err(e, "D1"), "ok");  // EX-35: D alone only selects the radius
    EXPECT_EQ(run_err(e, "G41 G01 X10 F600"), "ok");
    EXPECT_EQ(run_err(e, "G28 X0"),
              "test.nc:5:1: G28 is not allowed while cutter compensation (G41/G42) is active");
    EXPECT_EQ(run_err(e, "G51 X0 Y0 P2"),
              "test.nc:5:1: G51 is not allowed while cutter compensation (G41/G42) is active");
}

}  // namespace
}  // namespace interp
