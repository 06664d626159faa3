// Robustness property: any block the parser could hand over either executes or is rejected with
// interp::Error — never another exception, a crash, or a non-finite coordinate in the stream.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "interp/executor.hpp"

namespace interp {
namespace {

struct FiniteCheck : CanonSink {
    int bad = 0;
    int moves = 0;
    static bool finite(const AxisVec& v) {
        for (double d : v)
            if (!std::isfinite(d)) return false;
        return true;
    }
    void emit(const Canon& c) override {
        if (const auto* t = std::get_if<canon::Traverse>(&c.cmd)) {
            ++moves;
            bad += !finite(t->end_mm);
        } else if (const auto* f = std::get_if<canon::FeedLine>(&c.cmd)) {
            ++moves;
            bad += !finite(f->end_mm);
        } else if (const auto* a = std::get_if<canon::Arc>(&c.cmd)) {
            ++moves;
            bad += !finite(a->end_mm) || !std::isfinite(a->centre_mm[0]) ||
                   !std::isfinite(a->centre_mm[1]) || !std::isfinite(a->centre_mm[2]);
        }
    }
};

TEST(Robustness, RandomBlocksExecuteOrFailWithError) {
    const int g_codes[] = {
        gcode(0),   gcode(1),   gcode(2),   gcode(3),     gcode(4),     gcode(17),  gcode(18),
        gcode(19),  gcode(20),  gcode(21),  gcode(28),    gcode(40),    gcode(41),  gcode(43),
        gcode(49),  gcode(50),  gcode(51),  gcode(50, 1), gcode(51, 1), gcode(53),  gcode(54),
        gcode(56),  gcode(68),  gcode(69),  gcode(73),    gcode(80),    gcode(81),  gcode(83),
        gcode(84),  gcode(86),  gcode(90),  gcode(91),    gcode(92),    gcode(98),  gcode(99),
        gcode(34),  gcode(37),  gcode(903), gcode(904),   gcode(906),   gcode(916), gcode(921),
        gcode(922), gcode(923), gcode(992), gcode(12, 1), gcode(33)};
    const int m_codes[] = {0, 1, 2, 3, 5, 6, 8, 9, 10, 30, 801, 802, 901, 902, 903, 19};
    const char letters[] = "XYZABCIJKRPQFSTHDL";
    const double values[] = {0, 1, -1, 0.5, 10, -10, 99.999999, 100, 2500, -1e6, 1e-9, 45, 360};
    std::mt19937 rng(77);
    std::uniform_int_distribution<int> ng(0, 3), nm(0, 1), nw(0, 5);
    std::uniform_int_distribution<std::size_t> pick_g(0, std::size(g_codes) - 1),
        pick_m(0, std::size(m_codes) - 1), pick_l(0, sizeof letters - 2),
        pick_v(0, std::size(values) - 1);
    Settings s;
    s.tools.at(1).diameter_mm = 6;
    s.tools.at(1).offset_mm = {0, 0, 10};
    FiniteCheck sink;
    Executor exec(sink, BackendConfig{}, s);
    const std::string file = "fuzz.nc";
    int accepted = 0, rejected = 0;
    for (int i = 0; i < 20000; ++i) {
        Block b;
        b.loc = SourceLoc{file, i + 1, 1};
        for (int k = ng(rng); k > 0; --k) {
            b.g.push_back(g_codes[pick_g(rng)]);
            b.g_col.push_back(1);
        }
        for (int k = nm(rng); k > 0; --k) {
            b.m.push_back(m_codes[pick_m(rng)]);
            b.m_col.push_back(1);
        }
        for (int k = nw(rng); k > 0; --k) {
            const char l = letters[pick_l(rng)];
            b.words[letter_index(l)] = values[pick_v(rng)];
            b.word_col[letter_index(l)] = 1;
        }
        if (i % 50 == 0) b.msg = "m";
        if (i % 7 == 0) {
            b.kw.plc = 4;
            b.kw.level = 1;
            b.kw.f_axis[2] = -60;
            b.kw.p_axis[2] = 3;
            b.kw.l_axis[2] = i % 2;
        }
        try {
            exec.execute(b);
            ++accepted;
        } catch (const Error&) {
            ++rejected;
        }
    }
    EXPECT_EQ(sink.bad, 0);
    // Both outcomes must actually occur, or the generator is not testing anything.
    EXPECT_GT(accepted, 1000);
    EXPECT_GT(rejected, 1000);
    EXPECT_GT(sink.moves, 500);
}

}  // namespace
}  // namespace interp
