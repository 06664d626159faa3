#pragma once
// Puts the cutter radius compensation core (cutter_comp.hpp) between the executor and the sink.
//
// While compensation is on (or the compensator still holds moves), every committed block's
// commands go through here: moves in the compensation plane become compensator Moves, every
// other command becomes a Marker that keeps its place, and what the compensator releases is
// turned back into canonical commands with the tag of the block it belongs to. While
// compensation is off and nothing is held, commands pass straight to the sink.
//
// Compensation errors are found when a later block shows the corner (look-ahead), so they are
// reported at that later block, naming the earlier one too; the executor's state has already
// moved past the earlier block by then.
#include <cstdint>
#include <map>
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

    // One committed block's commands. `machine_before` is where the machine was before the
    // block. Throws interp::Error on a compensation error.
    void pass(const std::vector<Canon>& cmds, const CrcBlockState& s,
              const AxisVec& machine_before);

  private:
    struct Held {
        Canon canon;
    };
    void push_move(const Canon& c, const CrcBlockState& s, cutter::SourceTag tag);
    void release();
    [[noreturn]] void fail(const cutter::CompError& e) const;
    std::string with_lines(const std::string& text) const;

    CanonSink& sink_;
    cutter::Config cfg_;
    std::optional<cutter::Compensator> comp_;
    Plane plane_ = Plane::XY;
    std::map<cutter::SourceTag, Held> held_;  // commands by tag until the compensator lets go
    cutter::SourceTag next_tag_ = 1;
    AxisVec last_end_{};  // last emitted machine position (rotary axes of inserted pieces)
};

}  // namespace interp
