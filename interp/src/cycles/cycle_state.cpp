// The modal data rules of the canned cycles (FEATURES CC-3, CC-5…CC-14):
// what a block stores, when it drills, and where each repeat's hole is.

#include <fmt/format.h>

#include <cmath>

#include "hole_steps.hpp"

namespace interp::cycles {
namespace {

using detail::AxisMap;
using detail::HoleSpec;

struct CodeName {
    CycleCode code;
    int g;
};
constexpr CodeName kCodes[] = {
    {CycleCode::G73, 73}, {CycleCode::G74, 74}, {CycleCode::G76, 76}, {CycleCode::G81, 81},
    {CycleCode::G82, 82}, {CycleCode::G83, 83}, {CycleCode::G84, 84}, {CycleCode::G85, 85},
    {CycleCode::G86, 86}, {CycleCode::G87, 87}, {CycleCode::G88, 88}, {CycleCode::G89, 89},
};

bool needs_peck_depth(CycleCode code) {
    return code == CycleCode::G73 || code == CycleCode::G83;
}

bool has_hole_word(const CycleWords& w) {
    return w.axis_mm[0] || w.axis_mm[1] || w.axis_mm[2] || w.r_mm;
}

/// Resolves the stored data into one hole's parameters (position filled later).
/// The data every hole needs, also for a library cycle O(600+n) (its #FC3 and #FC5).
void check_data(const CycleData& d) {
    const CycleCode code = *d.code;
    const int g = g_number(code);
    if (!d.z_level_mm)
        throw CycleError(
            fmt::format("G{}: the hole bottom Z is missing (program Z in the first block of "
                        "the cycle)",
                        g));
    if (needs_peck_depth(code) && !d.q_mm)
        throw CycleError(fmt::format("G{}: the peck depth Q is missing", g));
    if (needs_peck_depth(code) && *d.q_mm == 0.0)
        throw CycleError(fmt::format("G{}: the peck depth Q must not be 0", g));
}

HoleSpec make_spec(const CycleData& d, const BlockContext& ctx, const CycleConfig& cfg,
                   Expansion& out) {
    const CycleCode code = *d.code;
    const int g = g_number(code);
    check_data(d);
    if (cfg.retract_mm < 0.0)
        throw CycleError(
            fmt::format("#FIXEDCYCLE_BACK must not be negative, it is {:g}", cfg.retract_mm));
    if (ctx.feed_mm_min <= 0.0) throw CycleError(fmt::format("G{}: no feed rate F programmed", g));

    HoleSpec spec{};
    spec.code = code;
    spec.axes = detail::axis_map(ctx.plane, cfg.drill_axis_follows_plane);
    spec.r_mm = d.r_level_mm.value_or(d.initial_level_mm);
    spec.z_mm = *d.z_level_mm;
    spec.initial_mm = d.initial_level_mm;
    spec.return_to_r = ctx.return_to_r;
    spec.q_mm = d.q_mm.value_or(0.0);
    spec.dwell_s = d.dwell_ms / 1000.0;
    spec.feed_mm_min = ctx.feed_mm_min;
    spec.spindle_rpm = ctx.spindle_rpm;
    spec.shift_dir = {0.0, 0.0};
    spec.shift_uv_mm.reset();
    if (code == CycleCode::G76 && cfg.g76_shift_uv) {
        spec.shift_uv_mm = d.shift_uv_mm;
        spec.shift_feed_mm_min =
            cfg.g76_shift_feed_mm_min > 0 ? cfg.g76_shift_feed_mm_min : ctx.feed_mm_min;
        const double len = std::hypot(d.shift_uv_mm[0], d.shift_uv_mm[1]);
        if (len > 0) spec.shift_dir = {d.shift_uv_mm[0] / len, d.shift_uv_mm[1] / len};
        else spec.shift_dir = detail::oss_shift(cfg);
    } else if (code == CycleCode::G76 || code == CycleCode::G87) {
        spec.shift_dir = detail::oss_shift(cfg);
    }
    // FEATURES A-10/EX-13: S0's own G87 example (Z-10 R-5) puts R above Z. Back boring needs R
    // (the hole bottom) below Z, but the example is a flow test, so the steps run as written.
    if (code == CycleCode::G87 && spec.r_mm > spec.z_mm)
        out.warnings.push_back(fmt::format(
            "G87 back boring: the R plane ({:g}) lies above Z ({:g}); R is meant to be the hole "
            "bottom, the steps run as programmed",
            spec.r_mm, spec.z_mm));
    if (code == CycleCode::G87 && ctx.return_to_r)
        out.warnings.push_back(
            "G87 returns to the initial level: the hole bottom is R, so G99 is treated as G98");
    return spec;
}

}  // namespace

std::optional<CycleCode> cycle_code_from_g(int g) {
    for (const auto& c : kCodes)
        if (c.g == g) return c.code;
    return std::nullopt;
}

int g_number(CycleCode code) {
    for (const auto& c : kCodes)
        if (c.code == code) return c.g;
    return 0;
}

CycleState::Plan CycleState::accept(std::optional<CycleCode> code, const CycleWords& words,
                                    const BlockContext& ctx, const CycleConfig& cfg) {
    if (!code && !data_.code) throw CycleError("no canned cycle is active");
    if (ctx.drill_axis_scaled)
        throw CycleError("a canned cycle cannot run while the drilling axis is scaled (G51)");
    const AxisMap ax = detail::axis_map(ctx.plane, cfg.drill_axis_follows_plane);

    // The initial level is latched only when cycle mode starts (CC-3), not when
    // one cycle code replaces another.
    if (code && !data_.code) data_.initial_level_mm = ctx.position_mm[ax.c];
    if (code) data_.code = code;

    // Under G91, R is measured from the initial level and Z from R (CC-5); both
    // are stored as absolute levels so a later G90/G91 switch moves nothing (CC-6).
    if (words.r_mm)
        data_.r_level_mm = ctx.incremental ? data_.initial_level_mm + *words.r_mm : *words.r_mm;
    if (const auto& z = words.axis_mm[ax.c]) {
        const double r_base = data_.r_level_mm.value_or(data_.initial_level_mm);
        data_.z_level_mm = ctx.incremental ? r_base + *z : *z;
    }
    if (words.q_mm) data_.q_mm = std::abs(*words.q_mm);
    if (words.u_mm) data_.shift_uv_mm[0] = *words.u_mm;
    if (words.v_mm) data_.shift_uv_mm[1] = *words.v_mm;
    if (words.p_ms) {
        if (*words.p_ms < 0.0)
            throw CycleError(fmt::format("dwell P must not be negative, got {:g}", *words.p_ms));
        data_.dwell_ms = *words.p_ms;
    }
    const double k = words.k.value_or(1.0);
    if (k != std::floor(k) || k < 0 || k > static_cast<double>(kMaxRepeat))
        throw CycleError(fmt::format("the repeat count K must be a whole number in 0…{}, got {:g}",
                                     kMaxRepeat, k));
    const auto repeat = static_cast<long>(k);
    return Plan{has_hole_word(words) && repeat > 0, repeat};
}

BlockHoles CycleState::start_block(std::optional<CycleCode> code, const CycleWords& words,
                                  const BlockContext& ctx, const CycleConfig& cfg) {
    CycleState next = *this;
    const Plan plan = next.accept(code, words, ctx, cfg);
    BlockHoles out;
    if (plan.drills) {
        Expansion warnings;
        const HoleSpec spec = make_spec(next.data_, ctx, cfg, warnings);
        out.warnings = std::move(warnings.warnings);
        const AxisMap ax = spec.axes;
        const std::array<double, 2> from{ctx.position_mm[ax.a], ctx.position_mm[ax.b]};
        HoleAt at;
        if (ctx.incremental) {
            // G91: every repeat steps by the increment (equally spaced holes, CC-10).
            const std::array<double, 2> step{words.axis_mm[ax.a].value_or(0.0),
                                             words.axis_mm[ax.b].value_or(0.0)};
            at = [from, step](long i) -> std::array<double, 2> {
                const auto n = static_cast<double>(i + 1);
                return {from[0] + n * step[0], from[1] + n * step[1]};
            };
        } else {
            // G90: the same hole again.
            const std::array<double, 2> hole{words.axis_mm[ax.a].value_or(from[0]),
                                             words.axis_mm[ax.b].value_or(from[1])};
            at = [hole](long) { return hole; };
        }
        out.holes = HoleRun(spec, ctx, cfg, plan.repeat, std::move(at));
    }
    *this = next;
    return out;
}

Expansion CycleState::run_block(std::optional<CycleCode> code, const CycleWords& words,
                                const BlockContext& ctx, const CycleConfig& cfg) {
    BlockHoles b = start_block(code, words, ctx, cfg);
    Expansion out;
    out.warnings = std::move(b.warnings);
    b.holes.drain_into(out);
    return out;
}

std::optional<FcVariables> CycleState::run_custom_block(std::optional<CycleCode> code,
                                                        const CycleWords& words,
                                                        const BlockContext& ctx,
                                                        const CycleConfig& cfg) {
    CycleState next = *this;
    const Plan plan = next.accept(code, words, ctx, cfg);
    if (plan.drills) check_data(next.data_);
    *this = next;
    if (!plan.drills) return std::nullopt;

    const AxisMap ax = detail::axis_map(ctx.plane, cfg.drill_axis_follows_plane);
    FcVariables fc{};
    // FC-2: under G91 the subprogram moves with G91 G65 … L=#FC11, so #FC1/#FC2
    // are the programmed increments; the levels are always absolute.
    if (ctx.incremental) {
        fc[1] = words.axis_mm[ax.a].value_or(0.0);
        fc[2] = words.axis_mm[ax.b].value_or(0.0);
    } else {
        fc[1] = words.axis_mm[ax.a].value_or(ctx.position_mm[ax.a]);
        fc[2] = words.axis_mm[ax.b].value_or(ctx.position_mm[ax.b]);
    }
    const CycleData& d = data_;
    fc[3] = d.z_level_mm.value_or(0.0);
    fc[4] = d.r_level_mm.value_or(d.initial_level_mm);
    fc[5] = d.q_mm.value_or(0.0);
    fc[6] = d.dwell_ms;
    fc[7] = ctx.feed_mm_min;
    fc[11] = static_cast<double>(plan.repeat);
    fc[12] = ctx.return_to_r ? 1.0 : 0.0;
    fc[13] = ctx.incremental ? 1.0 : 0.0;
    fc[14] = d.initial_level_mm;
    return fc;
}

BlockHoles CycleState::drill_pattern(long count, HoleAt hole_xy, const BlockContext& ctx,
                                     const CycleConfig& cfg) const {
    if (!data_.code)
        throw CycleError(
            "G34/35/36/37 instruction error: special canned cycle mismatch, none specified");
    if (ctx.drill_axis_scaled)
        throw CycleError("a canned cycle cannot run while the drilling axis is scaled (G51)");
    Expansion warnings;
    const HoleSpec spec = make_spec(data_, ctx, cfg, warnings);
    BlockHoles out;
    out.warnings = std::move(warnings.warnings);
    out.holes = HoleRun(spec, ctx, cfg, count, std::move(hole_xy));
    return out;
}

Expansion CycleState::drill_at(const std::vector<std::array<double, 2>>& holes,
                               const BlockContext& ctx, const CycleConfig& cfg) const {
    BlockHoles b = drill_pattern(static_cast<long>(holes.size()),
                                 [&holes](long i) { return holes[static_cast<std::size_t>(i)]; },
                                 ctx, cfg);
    Expansion out;
    out.warnings = std::move(b.warnings);
    b.holes.drain_into(out);
    return out;
}

HoleRun::HoleRun(const HoleSpec& spec, const BlockContext& ctx, const CycleConfig& cfg,
                 long count, HoleAt at)
    : spec_(spec), ctx_(ctx), cfg_(cfg), count_(count), at_(std::move(at)),
      position_(ctx.position_mm) {
    if (count_ > 0) detail::check_hole(spec_, ctx_, cfg_);
}

bool HoleRun::next(std::vector<Step>& steps) {
    steps.clear();
    if (next_ >= count_) return false;
    const std::array<double, 2> ab = at_(next_++);
    spec_.pos_a_mm = ab[0];
    spec_.pos_b_mm = ab[1];
    detail::append_hole(spec_, ctx_, cfg_, position_, steps);
    return true;
}

void HoleRun::drain_into(Expansion& out) {
    std::vector<Step> hole;
    while (next(hole)) out.steps.insert(out.steps.end(), hole.begin(), hole.end());
}

}  // namespace interp::cycles
