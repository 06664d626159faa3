// Cutter compensation through the whole interpreter (text -> Interpreter -> Executor ->
// CrcStage -> sink): a block rejected by a look-ahead error changes nothing (modal state,
// variables, output), the message names both blocks, and arcs of several turns are offset turn by
// turn. Expected positions are worked out by hand in each test's comment.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "interp/canon.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"
#include "interp/source.hpp"

namespace {

using namespace interp;

struct Recorder : CanonSink {
    std::vector<Canon> cmds;
    void emit(const Canon& c) override { cmds.push_back(c); }
};

// The parts of the executor's state a compensated block can change.
std::string state_text(const ExecState& s) {
    auto v = [](const AxisVec& a) { return fmt::format("{:.9g}", fmt::join(a, ",")); };
    return fmt::format(
        "motion={} plane={} inc={} feed={:g} rapid={:g} flood={} prog=({}) machine=({}) "
        "crc_side={} crc_d={} crc=({},{:g},{}) tool={} spindle={:g}",
        static_cast<int>(s.motion.motion), static_cast<int>(s.motion.plane), s.motion.incremental,
        s.feed.feed_mm_s, s.feed.rapid_mm_s, s.coolant.flood, v(s.pos.prog_mm), v(s.pos.machine_mm),
        static_cast<int>(s.crc_side), s.crc_d.value_or(-1), static_cast<int>(s.crc.side),
        s.crc.radius_mm, static_cast<int>(s.crc.plane), s.tool.current, s.spindle.rpm);
}

// Plane-motion commands as "kind x,y" (arcs: "arc x,y c cx,cy turns"), rounded to 1e-4.
std::vector<std::string> moves(const std::vector<Canon>& cmds) {
    auto r = [](double x) {
        const double v = std::round(x * 1e4) / 1e4;
        return v == 0 ? 0.0 : v;
    };
    std::vector<std::string> out;
    for (const Canon& c : cmds) {
        if (const auto* t = std::get_if<canon::Traverse>(&c.cmd))
            out.push_back(fmt::format("rapid {:g},{:g}", r(t->end_mm[0]), r(t->end_mm[1])));
        else if (const auto* f = std::get_if<canon::FeedLine>(&c.cmd))
            out.push_back(fmt::format("feed {:g},{:g}", r(f->end_mm[0]), r(f->end_mm[1])));
        else if (const auto* a = std::get_if<canon::Arc>(&c.cmd))
            out.push_back(fmt::format("arc {:g},{:g} z{:g} c{:g},{:g} t{}", r(a->end_mm[0]),
                                      r(a->end_mm[1]), r(a->end_mm[2]), r(a->centre_mm[0]),
                                      r(a->centre_mm[1]), a->turns));
    }
    return out;
}

struct Program {
    Recorder sink;
    Executor exec;
    Interpreter in;
    explicit Program(const std::string& program, BackendConfig cfg = {})
        : exec(sink, cfg, radius5()), in(exec, exec) {
        in.open(Source::from_string("prog.nc", program));
    }
    static Settings radius5() {
        Settings s;
        s.tools.at(1).diameter_mm = 10;
        return s;
    }
    // Steps one line; returns the error text, or "" when it ran.
    std::string step() {
        try {
            in.step();
        } catch (const Error& e) {
            return e.what();
        }
        return "";
    }
};

// FEATURES EX-10 program 1, with a variable assignment and M08 in the rejected block, then
// program 2's correct cancel. r = 5: start-up to the perpendicular of line 3 at its start,
// (10, 15); line 3 at y = 15 to (20, 15); the cancel from there to (0, 0).
TEST(CutterCompExec, RejectedBlockChangesNothing) {
    Program run(
        "G92 G0 X0 Y0\n"
        "G0 G41 X10 Y10 D01 F1000\n"
        "G1 X20 Y10\n"
        "#1=7 G0 G40 X0 Y10 M08\n"
        "G0 G40 X0 Y0\n"
        "M30\n");
    for (int line = 1; line <= 3; ++line) ASSERT_EQ(run.step(), "") << line;
    const std::string before = state_text(run.exec.state());
    const std::size_t emitted = run.sink.cmds.size();
    EXPECT_EQ(run.step(), "prog.nc:4:1: cutter comp: path reversal (with the move at line 3)");
    EXPECT_EQ(state_text(run.exec.state()), before);
    EXPECT_EQ(run.sink.cmds.size(), emitted);
    EXPECT_FALSE(run.in.variables().numbered_if_set(1).has_value());
    // Line 3 is still held: the correct cancel of program 2 finishes it as if line 4 never was.
    EXPECT_EQ(run.step(), "");
    EXPECT_EQ(run.step(), "");
    EXPECT_EQ(moves(run.sink.cmds),
              (std::vector<std::string>{"rapid 10,15", "feed 20,15", "rapid 0,0"}));
    for (const Canon& c : run.sink.cmds)
        EXPECT_FALSE(std::holds_alternative<canon::Coolant>(c.cmd)) << to_text(c);
}

// The error of a gouge found at the second block after the held one: the rejected block is the
// one that showed it; the message names the held move and the contour it would cut.
TEST(CutterCompExec, GougeNamesTheHeldMoveAndTheContour) {
    // Inside a 20×20 square with r = 5 (G41 on a CCW square): the perpendicular cancel from the
    // last edge would end at (5, 0), on the bottom edge (line 3).
    Program run(
        "G0 X10 Y10\n"
        "G41 G1 X0 Y0 D1 F600\n"
        "X20\n"
        "Y20\n"
        "X0\n"
        "Y0\n"
        "G40 X10 Y10\n");
    for (int line = 1; line <= 6; ++line) ASSERT_EQ(run.step(), "") << line;
    const std::string before = state_text(run.exec.state());
    EXPECT_EQ(run.step(),
              "prog.nc:7:1: cutter comp: gouge: the tool (radius 5) would come within 0 of the "
              "contour of line 3 (with the move at line 6)");
    EXPECT_EQ(state_text(run.exec.state()), before);
}

// A plane change while compensation is on is refused in the block that changes it.
TEST(CutterCompExec, PlaneChangeIsRefusedWhereItIsWritten) {
    Program run(
        "G0 X-10 Y0\n"
        "G41 G1 X0 Y0 D1 F600\n"
        "X20\n"
        "G18\n"
        "G40 X30\n");
    for (int line = 1; line <= 3; ++line) ASSERT_EQ(run.step(), "") << line;
    const std::string before = state_text(run.exec.state());
    EXPECT_EQ(run.step(),
              "prog.nc:4:1: cutter comp: the plane changed from G17 to G18 while compensation is "
              "active; cancel it with G40 first (with the move at line 3)");
    EXPECT_EQ(state_text(run.exec.state()), before);
    EXPECT_EQ(run.step(), "");
    // r = 5 left of +X: y = 5; the cancel leaves from the perpendicular at (20, 5).
    EXPECT_EQ(moves(run.sink.cmds),
              (std::vector<std::string>{"rapid -10,0", "feed 0,5", "feed 20,5", "feed 30,0"}));
}

// ARC-9 (V5.4): `G03 X0 Y30 R30 Z-20 K10` from (30, 0) sweeps 90° plus n = round(20/10 − 0.25)
// = 2 extra turns, 810° in all, Z falling linearly. With G41 (left of CCW travel = the centre
// side) and r = 5 each turn is offset on its own to radius 25: two full circles back to (25, 0),
// ending at z = −20·360/810 = −8.8889 and −20·720/810 = −17.7778, then the last quarter to
// (0, 25). The start-up ends on the perpendicular at (30, 0) (tangent +Y, left −X): (25, 0); the
// cancel leaves from the perpendicular at (0, 30) (tangent −X, left −Y): (0, 25).
TEST(CutterCompExec, EachTurnOfAHelixIsOffset) {
    BackendConfig cfg;
    cfg.v54_compat = true;
    Program run(
        "G90 G17 G0 X40 Y0 Z0\n"
        "G41 G1 X30 Y0 D1 F600\n"
        "G03 X0 Y30 R30 Z-20 K10\n"
        "G40 G1 X0 Y40\n"
        "M30\n",
        cfg);
    while (!run.in.finished()) ASSERT_EQ(run.step(), "");
    EXPECT_EQ(moves(run.sink.cmds),
              (std::vector<std::string>{"rapid 40,0", "feed 25,0", "arc 25,0 z-8.8889 c0,0 t1",
                                        "arc 25,0 z-17.7778 c0,0 t1", "arc 0,25 z-20 c0,0 t1",
                                        "feed 0,40"}));
}

}  // namespace
