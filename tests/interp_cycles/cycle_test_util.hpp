#pragma once
// Small helpers shared by the canned-cycle tests.

#include <string>
#include <vector>

#include "interp/cycles.hpp"

namespace cycle_test {

using namespace interp::cycles;

inline std::vector<std::string> texts(const Expansion& e) {
    std::vector<std::string> out;
    for (const auto& s : e.steps) out.push_back(to_string(s));
    return out;
}

/// The context of the manual's examples: G90, tool at X0 Y0 Z10, F800, S600 M03.
inline BlockContext manual_context() {
    BlockContext ctx;
    ctx.position_mm = {0, 0, 10};
    ctx.feed_mm_min = 800;
    ctx.spindle_rpm = 600;
    ctx.spindle = Spindle::Cw;
    return ctx;
}

/// The tool position after an expansion (last move's end, or unchanged).
inline Vec3 end_position(const Expansion& e, Vec3 start) {
    for (const auto& s : e.steps) {
        if (const auto* r = std::get_if<Rapid>(&s)) start = r->to_mm;
        if (const auto* f = std::get_if<Feed>(&s)) start = f->to_mm;
    }
    return start;
}

struct Words {
    CycleWords w;
    Words& x(double v) {
        w.axis_mm[0] = v;
        return *this;
    }
    Words& y(double v) {
        w.axis_mm[1] = v;
        return *this;
    }
    Words& z(double v) {
        w.axis_mm[2] = v;
        return *this;
    }
    Words& r(double v) {
        w.r_mm = v;
        return *this;
    }
    Words& q(double v) {
        w.q_mm = v;
        return *this;
    }
    Words& p(double v) {
        w.p_ms = v;
        return *this;
    }
    Words& k(double v) {
        w.k = v;
        return *this;
    }
    operator CycleWords() const { return w; }
};

}  // namespace cycle_test
