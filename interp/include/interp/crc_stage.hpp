#pragma once
// Puts the cutter radius compensation core (cutter_comp.hpp) between the executor and the sink.
//
// While compensation is on (or the compensator still holds moves), every block's commands go
// through here: moves in the compensation plane become compensator Moves (an arc of several
// turns becomes one Move per turn), every other command becomes a Marker that keeps its place,
// and what the compensator releases is turned back into canonical commands with the location of
// the block it belongs to. While compensation is off and nothing is held, commands pass straight
// to the sink.
//
// Compensation errors are found when a later block shows the corner (look-ahead), so they are
// reported at that later block and name the earlier one: "file:line:col: cutter comp: path
// reversal (with the move at line 3)". A block is staged first (stage(), on a copy of the
// compensator) and emitted only when the executor commits it (emit_staged()), so the block at
// which an error is raised changes nothing: not this stage, not the executor's state, not the
// output. The earlier block stays committed and held, as it was before.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "interp/canon.hpp"
#include "interp/cutter_comp.hpp"

namespace interp {

struct CrcBlockState {
    cutter::Side side = cutter::Side::Off;
    double radius_mm = 0;
    Plane plane = Plane::XY;
};

class CrcStage {
  public:
    explicit CrcStage(CanonSink& sink, cutter::Config cfg = {}) : sink_(sink), cfg_(cfg) {}

    // True while commands must go through the compensator.
    bool engaged() const { return comp_.has_value(); }

    // Runs one block's commands through a copy of the compensator. `machine_before` is where the
    // machine was before the block. Throws interp::Error on a compensation error; then nothing
    // here changed and nothing was emitted. `cmds` must stay alive until emit_staged().
    void stage(const std::vector<Canon>& cmds, const CrcBlockState& s,
               const AxisVec& machine_before);
    // Emits what the staged block released and makes the staged state current. Once per stage().
    void emit_staged();
    // stage() then emit_staged(), for callers with nothing to commit in between.
    void pass(const std::vector<Canon>& cmds, const CrcBlockState& s,
              const AxisVec& machine_before) {
        stage(cmds, s, machine_before);
        emit_staged();
    }

  private:
    void push_move(cutter::Compensator& comp, const Canon& c, const CrcBlockState& s,
                   const AxisVec& start, cutter::SourceTag tag) const;
    void release(const std::vector<cutter::Output>& outputs);
    const Canon* held(cutter::SourceTag tag) const;
    [[noreturn]] void fail(const cutter::CompError& e, const SourceLoc& fallback) const;
    [[noreturn]] void fail_plane_change(const CrcBlockState& s, const SourceLoc& loc) const;

    CanonSink& sink_;
    cutter::Config cfg_;
    std::optional<cutter::Compensator> comp_;
    std::optional<cutter::Compensator> spare_;  // storage reused by the next stage()
    Plane plane_ = Plane::XY;
    // Commands by tag (tags are consecutive): those the compensator may still release, and a few
    // released ones that error messages may still name.
    std::deque<Canon> held_;
    cutter::SourceTag held_base_ = 1;  // the tag of held_.front()
    cutter::SourceTag next_tag_ = 1;
    AxisVec last_end_{};  // last emitted machine position (rotary axes of inserted pieces)

    // The staged block, between stage() and emit_staged().
    struct Staged {
        const std::vector<Canon>* direct = nullptr;  // compensation off: pass these through
        std::optional<cutter::Compensator> comp;     // the compensator after the block
        std::vector<cutter::Output> outputs;
        bool fresh = false;      // compensation engaged in this block
        bool disengage = false;  // compensation fully off after this block
        Plane plane = Plane::XY;
        AxisVec machine_before{};
    };
    Staged staged_;
};

}  // namespace interp
