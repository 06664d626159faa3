#include "ngc_program.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <variant>

#include "canon_geometry.hpp"
#include "interp/canon.hpp"
#include "interp/executor.hpp"
#include "interp/interpreter.hpp"
#include "motion/geometry.hpp"

namespace motion::bench {
namespace {

// The interpreter's machine axes (X Y Z A B C) are the first of the planner's nine.
AxisArray to_axes(const interp::AxisVec& v) {
    AxisArray out{};
    for (int k = 0; k < interp::kMachineAxes && k < kAxes; ++k) out[k] = v[k];
    return out;
}

// Collects motion; commands without a meaning for the planner (spindle, coolant, I/O, tool
// changes, messages) are skipped, as the bench measures motion only.
class SegmentSink final : public interp::CanonSink {
  public:
    SegmentSink(BenchProgram& prog, double tolerance_mm)
        : prog_(prog), default_tolerance_mm_(tolerance_mm), tolerance_mm_(tolerance_mm) {}

    void emit(const interp::Canon& c) override {
        std::visit([&](const auto& cmd) { handle(c.loc, cmd); }, c.cmd);
    }

  private:
    void handle(const interp::SourceLoc& loc, const interp::canon::Traverse& t) {
        PathSegment seg = base(loc, t.end_mm, t.flags);
        seg.rapid = true;
        add(seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::FeedLine& f) {
        PathSegment seg = base(loc, f.end_mm, f.flags);
        seg.feed_mm_s = feed_mm_s_;
        add(seg);
    }
    void handle(const interp::SourceLoc& loc, const interp::canon::Arc& a) {
        PathSegment seg = base(loc, a.end_mm, a.flags);
        motioncomp::set_arc_geometry(seg, a);
        seg.feed_mm_s = feed_mm_s_;
        add(seg);
    }
    void handle(const interp::SourceLoc&, const interp::canon::SetFeedRate& f) {
        feed_mm_s_ = f.feed_mm_s;
    }
    // G61 (exact path: tolerance 0) or G64 P (P <= 0: the bench's default tolerance).
    void handle(const interp::SourceLoc&, const interp::canon::SetBlending& b) {
        tolerance_mm_ =
            b.exact ? 0.0 : (b.tolerance_mm > 0 ? b.tolerance_mm : default_tolerance_mm_);
    }
    // A dwell stops the machine: the move before it ends at rest.
    void handle(const interp::SourceLoc&, const interp::canon::Dwell& d) {
        if (!prog_.segments.empty()) prog_.segments.back().exact_stop = true;
        prog_.dwell_s += d.seconds;
    }
    template <class Other>
    void handle(const interp::SourceLoc&, const Other&) {}

    PathSegment base(const interp::SourceLoc& loc, const interp::AxisVec& end,
                     const interp::canon::MoveFlags& flags) const {
        PathSegment seg;
        seg.end_mm = to_axes(end);
        seg.tolerance_mm = tolerance_mm_;
        seg.exact_stop = flags.exact_stop;  // G09
        seg.line = loc.line;
        return seg;
    }
    void add(const PathSegment& seg) { prog_.segments.push_back(seg); }

    BenchProgram& prog_;
    double default_tolerance_mm_;
    double tolerance_mm_;  // the active G61 / G64 P
    double feed_mm_s_ = 0;
};

}  // namespace

BenchProgram read_program(const std::string& path, double default_tolerance_mm) {
    BenchProgram prog;
    SegmentSink sink(prog, default_tolerance_mm);
    interp::BackendConfig backend;
    // Rapids go straight, as in LinuxCNC (NcStudio's Z-first split would add corners that the
    // programs compared against LinuxCNC do not have).
    backend.g00_z_split = false;
    interp::Executor exec(sink, backend);
    interp::InterpreterOptions options;
    options.main_m99_loops = false;  // a looping program would never end
    interp::Interpreter in(exec, exec, options);
    in.open(path);
    in.run();
    return prog;
}

double programmed_length_mm(const PathSegment& seg, const AxisArray& start) {
    Element e = seg.kind == SegmentKind::Arc ? make_arc(start, seg) : make_line(start, seg.end_mm);
    return e.length_mm;
}

std::vector<PreparedSegment> plan_all(const PlannerConfig& cfg, const BenchProgram& prog) {
    Planner planner(cfg, prog.start_mm);
    std::vector<PreparedSegment> out;
    PreparedSegment rec;
    for (const PathSegment& seg : prog.segments) {
        planner.push(seg);
        while (planner.pop(rec)) out.push_back(rec);
    }
    planner.finish();
    while (planner.pop(rec)) out.push_back(rec);
    return out;
}

}  // namespace motion::bench
