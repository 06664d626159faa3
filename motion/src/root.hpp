// Root finding shared by the planner's solvers.
#pragma once

#include <cmath>

namespace motion::detail {

struct Bracket {
    double lo, hi;
    bool found;  // accept() took a point: lo == hi == that point
};

// Regula falsi with the Illinois modification on an increasing f, with f(lo) = flo < 0 <
// f(hi) = fhi: keeps the root bracketed and converges in a few steps where bisection needs
// fifty. Stops when accept(x, f(x)) holds or the bracket is narrower than min_width.
template <class F, class Accept>
Bracket illinois(F&& f, double lo, double flo, double hi, double fhi, double min_width, Accept&& accept) {
    int side = 0;
    for (int k = 0; k < 100 && hi - lo > min_width; ++k) {
        double x = (lo * fhi - hi * flo) / (fhi - flo);
        if (!(x > lo && x < hi)) x = (lo + hi) / 2;
        const double fx = f(x);
        if (accept(x, fx)) return {x, x, true};
        if (fx < 0) {
            lo = x, flo = fx;
            if (side == -1) fhi /= 2;
            side = -1;
        } else {
            hi = x, fhi = fx;
            if (side == 1) flo /= 2;
            side = 1;
        }
    }
    return {lo, hi, false};
}

}  // namespace motion::detail
