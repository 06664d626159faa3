// siggen: sine, cosine, triangle, sawtooth and square waves plus a clock bit, all from one
// phase accumulator, LinuxCNC-compatible (`loadrt siggen`, function siggen.N.update).
//
// The phase `index_` runs 0 -> 1 once per cycle:
//
//   index     0    0.25   0.5   0.75   1
//   sine      0     +1     0     -1    0
//   cosine   +1      0    -1      0   +1        (leads sine by 90 degrees)
//   square   -1     -1    -1     +1   +1        (+1 while index > 0.5)
//   triangle +1      0    -1      0   +1        (peaks with cosine)
//   sawtooth -1   -0.5     0   +0.5   +1        (drops when triangle peaks)
//
// each scaled by amplitude and shifted by offset. reset parks the phase at 0.5.
// Differences from LinuxCNC: a negative frequency runs the waves backwards (LinuxCNC lets the
// phase run below 0 without wrapping), the frequency is clamped to the Nyquist limit (0.5 / period)
// locally instead of being written back into the `frequency` input pin, and pi is exact
// (LinuxCNC uses 3.1415927, which puts sine's zero crossings ~5e-8 off zero).
#include <cmath>
#include <numbers>

#include "hal/component.hpp"

namespace {

struct Siggen : hal::Instance {
    hal::Out<double> square{this, "square"};
    hal::Out<double> sawtooth{this, "sawtooth"};
    hal::Out<double> triangle{this, "triangle"};
    hal::Out<double> sine{this, "sine"};
    hal::Out<double> cosine{this, "cosine"};
    hal::Out<bool> clock{this, "clock"};
    hal::In<double> frequency{this, "frequency", 1.0};
    hal::In<double> amplitude{this, "amplitude", 1.0};
    hal::In<double> offset{this, "offset", 0.0};
    hal::In<bool> reset{this, "reset"};

    Siggen() { function<&Siggen::update>("update"); }

    void update(hal::Period period) noexcept {
        double step = frequency * period.s;  // fraction of a cycle per period
        if (step > 0.5) step = 0.5;
        if (step < -0.5) step = -0.5;
        index_ = reset ? 0.5 : index_ + step;
        if (index_ >= 1.0) index_ -= 1.0;
        if (index_ < 0.0) index_ += 1.0;

        const double amp = amplitude;
        const double off = offset;
        const bool high = index_ > 0.5;
        const double sq = high ? 1.0 : -1.0;
        const double saw = index_ * 2.0 - 1.0;
        const double angle = index_ * 2.0 * std::numbers::pi;
        clock = high;
        square = sq * amp + off;
        sawtooth = saw * amp + off;
        triangle = (saw * 2.0 * sq - 1.0) * amp + off;
        sine = std::sin(angle) * amp + off;
        cosine = std::cos(angle) * amp + off;
    }

  private:
    double index_ = 0.0;
};

}  // namespace

HAL_COMPONENT(siggen, Siggen, "signal generator")
