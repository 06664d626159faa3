// Seeded property test: for random cycles, levels, modes and repeat counts,
// every generated move stays between the R plane, the initial level and Z;
// cutting moves stay between R and Z; each hole reaches Z exactly; the tool ends
// at the return level (initial for G98 and G87, R for G99).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "cycle_test_util.hpp"

namespace {

using namespace cycle_test;

constexpr CycleCode kAll[] = {CycleCode::G73, CycleCode::G74, CycleCode::G76, CycleCode::G81,
                              CycleCode::G82, CycleCode::G83, CycleCode::G84, CycleCode::G85,
                              CycleCode::G86, CycleCode::G87, CycleCode::G88, CycleCode::G89};

TEST(CycleProperty, MotionStaysBetweenRInitialLevelAndZ) {
    std::mt19937 rng(20261121);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int holes_checked = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const CycleCode code = kAll[trial % std::size(kAll)];
        const bool back = code == CycleCode::G87;
        BlockContext ctx;
        ctx.feed_mm_min = 100 + 1000 * u(rng);
        ctx.spindle = code == CycleCode::G74 ? Spindle::Ccw : Spindle::Cw;
        ctx.incremental = u(rng) < 0.5;
        ctx.return_to_r = u(rng) < 0.5;
        const double initial = 50 * u(rng);
        ctx.position_mm = {100 * u(rng) - 50, 100 * u(rng) - 50, initial};
        CycleConfig cfg;
        cfg.retract_mm = 2 * u(rng);
        cfg.oss_direction = static_cast<int>(4 * u(rng));
        cfg.g88_retract = u(rng) < 0.5 ? G88Retract::Feed : G88Retract::Manual;
        // Absolute levels: R below the initial level, Z below R (G87: between R and
        // the initial level).
        const double r_abs = initial - 20 * u(rng);
        const double z_abs =
            back ? r_abs + (initial - r_abs) * (0.05 + 0.95 * u(rng)) : r_abs - 0.1 - 30 * u(rng);
        const long k = 1 + static_cast<long>(3 * u(rng));
        Words w;
        w.x(20 * u(rng) - 10).y(20 * u(rng) - 10).q(0.2 + 5 * u(rng)).p(1000 * u(rng)).k(k);
        if (ctx.incremental)
            w.r(r_abs - initial).z(z_abs - r_abs);
        else
            w.r(r_abs).z(z_abs);

        CycleState st;
        const Expansion e = st.run_block(code, w, ctx, cfg);
        const double lo = std::min({r_abs, z_abs, initial}) - 1e-9;
        const double hi = std::max({r_abs, z_abs, initial}) + 1e-9;
        int reached_z = 0;
        for (const Step& s : e.steps) {
            if (const auto* r = std::get_if<Rapid>(&s)) {
                EXPECT_GE(r->to_mm[2], lo);
                EXPECT_LE(r->to_mm[2], hi);
            }
            if (const auto* f = std::get_if<Feed>(&s)) {
                EXPECT_GE(f->to_mm[2], std::min(r_abs, z_abs) - 1e-9);
                EXPECT_LE(f->to_mm[2], std::max(r_abs, z_abs) + 1e-9);
                if (std::abs(f->to_mm[2] - z_abs) < 1e-9) ++reached_z;
            }
        }
        ASSERT_EQ(reached_z, k) << "G" << g_number(code) << " trial " << trial;
        const double ret = (ctx.return_to_r && !back) ? r_abs : initial;
        EXPECT_NEAR(end_position(e, ctx.position_mm)[2], ret, 1e-9)
            << "G" << g_number(code) << " trial " << trial;
        holes_checked += reached_z;
    }
    EXPECT_GT(holes_checked, 3000);
}

}  // namespace

namespace {

// Random word combinations over several blocks: each block either succeeds with
// finite moves or throws CycleError, and a throwing block leaves the data as it was.
TEST(CycleProperty, ArbitraryWordsFailCleanly) {
    std::mt19937 rng(99);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto maybe = [&](double p, double lo, double hi) -> std::optional<double> {
        if (u(rng) >= p) return std::nullopt;
        return lo + (hi - lo) * u(rng);
    };
    int errors = 0, blocks = 0;
    for (int program = 0; program < 500; ++program) {
        CycleState st;
        BlockContext ctx;
        ctx.position_mm = {0, 0, 10};
        ctx.feed_mm_min = u(rng) < 0.9 ? 500 : 0;
        ctx.spindle = static_cast<Spindle>(static_cast<int>(3 * u(rng)));
        CycleConfig cfg;
        cfg.oss_direction = static_cast<int>(6 * u(rng)) - 1;
        cfg.retract_mm = 2 * u(rng) - 0.2;
        for (int b = 0; b < 6; ++b) {
            CycleWords w;
            w.axis_mm = {maybe(0.5, -20, 20), maybe(0.5, -20, 20), maybe(0.5, -30, 15)};
            w.r_mm = maybe(0.5, -10, 12);
            w.q_mm = maybe(0.4, -3, 3);
            w.p_ms = maybe(0.3, -100, 2000);
            if (u(rng) < 0.3) w.k = static_cast<long>(6 * u(rng)) - 1;
            ctx.incremental = u(rng) < 0.3;
            ctx.return_to_r = u(rng) < 0.5;
            std::optional<CycleCode> code;
            if (u(rng) < 0.4 || !st.active()) code = kAll[static_cast<int>(12 * u(rng))];
            const CycleData before = st.data();
            ++blocks;
            try {
                const Expansion e = st.run_block(code, w, ctx, cfg);
                ASSERT_LE(e.steps.size(), 2000000u);
                ctx.position_mm = end_position(e, ctx.position_mm);
                for (double v : ctx.position_mm) ASSERT_TRUE(std::isfinite(v));
            } catch (const CycleError&) {
                ++errors;
                EXPECT_EQ(st.data().code, before.code);
                EXPECT_EQ(st.data().z_level_mm, before.z_level_mm);
                EXPECT_EQ(st.data().r_level_mm, before.r_level_mm);
            }
        }
    }
    EXPECT_GT(errors, 100);
    EXPECT_LT(errors, blocks);
}

}  // namespace
