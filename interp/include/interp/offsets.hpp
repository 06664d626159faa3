#pragma once
// Persistent coordinate offsets (machine coordinates, mm/deg). machine = work + wcs[selected] +
// common + g92 (+ the non-persistent G992 offset and the tool offset, held by the executor).
#include <array>

#include "interp/canon.hpp"

namespace interp {

inline constexpr int kWorkSystems = 6;  // G54..G59

struct WorkOffsets {
    std::array<AxisVec, kWorkSystems> wcs{};  // origins of G54..G59
    AxisVec common{};  // NcStudio common offset (G922 P-4), includes the external offset
    AxisVec g92{};     // G92 shift of every work system
    bool operator==(const WorkOffsets&) const = default;
};

}  // namespace interp
