// Modal bookkeeping of public.dat canned cycles (FEATURES CC-19, FC-1, FC-2): the same data
// rules as the built-in cycles, feeding #FC variables instead of steps.

#include "interp/cycles.hpp"

namespace interp::cycles {

std::optional<CustomCycles::Run> CustomCycles::block(const BlockInfo& b) {
    CustomCycles next = *this;  // a block that throws changes nothing
    std::optional<Run> run = next.apply(b);
    *this = std::move(next);
    return run;
}

std::optional<CustomCycles::Run> CustomCycles::apply(const BlockInfo& b) {
    if (b.cancels) {
        g_.reset();
        data_.cancel();
    }
    if (b.f) feed_ = *b.f;
    if (!b.custom_g && !g_) return std::nullopt;

    std::optional<CycleCode> code;
    if (b.custom_g) {
        code = cycle_code_from_g(*b.custom_g);
        // A code outside G73…G89 (public.dat may define any G n) has no cycle data: it runs
        // once with the block's words, like any other custom G code.
        if (!code) {
            Run run{*b.custom_g, {}};
            const auto& w = b.words;
            run.fc[1] = w.axis_mm[0].value_or(0.0);
            run.fc[2] = w.axis_mm[1].value_or(0.0);
            run.fc[3] = w.axis_mm[2].value_or(0.0);
            run.fc[4] = w.r_mm.value_or(0.0);
            run.fc[5] = w.q_mm.value_or(0.0);
            run.fc[6] = w.p_ms.value_or(0.0);
            run.fc[7] = feed_;
            run.fc[11] = w.k.value_or(1.0);
            run.fc[12] = b.ctx.return_to_r ? 1.0 : 0.0;
            run.fc[13] = b.ctx.incremental ? 1.0 : 0.0;
            run.fc[14] = b.ctx.position_mm[2];
            return run;
        }
        // Another cycle code replaces the running one but keeps the initial level (CC-3).
        g_ = *b.custom_g;
    }
    BlockContext ctx = b.ctx;
    ctx.feed_mm_min = feed_;
    std::optional<FcVariables> fc = data_.run_custom_block(code, b.words, ctx, CycleConfig{});
    if (!fc) return std::nullopt;
    return Run{*g_, *fc};
}

}  // namespace interp::cycles
