// mux4: four-way selector for floats, LinuxCNC-compatible (`loadrt mux4`, function mux4.N).
// sel0 is the low bit of the index, sel1 the high bit.
#include "hal/component.hpp"

namespace {

struct Mux4 : hal::Instance {
    hal::In<bool> sel0{this, "sel0"};
    hal::In<bool> sel1{this, "sel1"};
    hal::Out<double> out{this, "out"};
    hal::Array<hal::In<double>> in{this, "in{}", 4};

    void update(hal::Period) noexcept {
        const unsigned index = (sel1 ? 2u : 0u) + (sel0 ? 1u : 0u);
        out = in[index].get();
    }
};

}  // namespace

HAL_COMPONENT(mux4, Mux4, "Select from one of four input values")
