#include "motion/profile.hpp"
#include "root.hpp"

#include <algorithm>
#include <cmath>

namespace motion {
namespace {

bool jerk_limited(const TangentLimits& lim) {
    return lim.jerk_mm_s3 > 0;
}

// Appends phases that change speed from v0 to v1 with zero acceleration at both ends.
class PhaseWriter {
  public:
    explicit PhaseWriter(Profile1D& p) : p_(p) {}

    // Jerk-limited (lim.jerk_mm_s3 > 0): +J, (0), -J.
    void ramp(double v0, double v1, const TangentLimits& lim) {
        double dv = v1 - v0;
        if (dv == 0) return;
        double sign = dv > 0 ? 1.0 : -1.0;
        dv = std::fabs(dv);
        double a = lim.acc_mm_s2;
        double j = lim.jerk_mm_s3;
        if (dv >= a * a / j) {
            push(0, sign * j, a / j);
            push(sign * a, 0, dv / a - a / j);
            push(sign * a, -sign * j, a / j);
        } else {
            double tj = std::sqrt(dv / j);
            push(0, sign * j, tj);
            push(sign * j * tj, -sign * j, tj);
        }
        v_ = v1;  // removes the rounding drift of the integrated speed
        a_ = 0;
    }

    // Jerk-unlimited: constant +-a for t_s = |v1 - v0| / a, which the caller has computed
    // already (trapezoid_ramps).
    void ramp_unlimited(double v0, double v1, double a, double t_s) {
        double dv = v1 - v0;
        if (dv == 0) return;
        double sign = dv > 0 ? 1.0 : -1.0;
        push_without_jerk(sign * a, t_s);
    }

    void cruise(double duration) { push_without_jerk(0, duration); }

    void start(double v) { v_ = v; }

    double time() const { return t_; }

  private:
    // a0 is the acceleration at the phase start; it is passed explicitly so that phases that
    // begin at a nominal value (0 or +-A) do not inherit rounding from the previous phase.
    void push(double a0, double j, double dt) {
        if (dt <= 0) return;
        ProfilePhase& ph = p_.phases[p_.count++];
        ph = {t_, s_, v_, a0, j};
        s_ += v_ * dt + a0 * dt * dt / 2 + j * dt * dt * dt / 6;
        v_ += a0 * dt + j * dt * dt / 2;
        a_ = a0 + j * dt;
        t_ += dt;
        p_.peak_a_mm_s2 = std::max({p_.peak_a_mm_s2, std::fabs(a0), std::fabs(a_)});
        p_.peak_j_mm_s3 = std::max(p_.peak_j_mm_s3, std::fabs(j));
    }

    // push(a0, 0, dt), the trapezoids' phases: with j = +0 each jerk term (j dt^3 / 6,
    // j dt^2 / 2, j dt) is +0 for a finite dt and NaN otherwise (dt > 0 or NaN here), as 0 * dt
    // is. So one product stands for them, with the sums in the same order: the same values,
    // without three products and a division per term (the division by 6 was on every phase).
    void push_without_jerk(double a0, double dt) {
        if (dt <= 0) return;
        ProfilePhase& ph = p_.phases[p_.count++];
        ph = {t_, s_, v_, a0, 0};
        const double jerk_terms = 0 * dt;
        s_ += v_ * dt + a0 * dt * dt / 2 + jerk_terms;
        v_ += a0 * dt + jerk_terms;
        a_ = a0 + jerk_terms;
        t_ += dt;
        p_.peak_a_mm_s2 = std::max({p_.peak_a_mm_s2, std::fabs(a0), std::fabs(a_)});
        p_.peak_j_mm_s3 = std::max(p_.peak_j_mm_s3, 0.0);
    }

    Profile1D& p_;
    double t_ = 0, s_ = 0, v_ = 0, a_ = 0;
};

// The largest peak speed in [lo, hi] whose two ramps fit in length (jerk-limited). The ramp
// distances grow with the peak speed; regula falsi with the Illinois modification keeps the
// root bracketed and converges in a few steps where bisection needs fifty.
double peak_speed_for_length(double length, double v_in, double v_out, double lo, double hi,
                             const TangentLimits& lim) {
    auto excess = [&](double vp) {
        return ramp_distance_mm(v_in, vp, lim) + ramp_distance_mm(vp, v_out, lim) - length;
    };
    const double tol = 1e-12 * std::max(length, 1e-9);
    double flo = excess(lo), fhi = excess(hi);
    if (flo >= 0) return lo;
    // The answer must fit: accept only a point on the short side (excess <= 0).
    auto b = detail::illinois(excess, lo, flo, hi, fhi, 1e-14 * hi,
                              [&](double, double f) { return std::fabs(f) <= tol && f <= 0; });
    return b.lo;
}

// The two ramps of a trapezoid from v_in to the peak vp and on to v_out at acceleration a:
// their times and the length they need, computed with the operations of ramp_time_s() and
// ramp_distance_mm() (needed = ramp_distance_mm(v_in, vp) + ramp_distance_mm(vp, v_out)), so
// the profile is the one those give. Each is computed once: the length decides the peak and the
// cruise, the times are the ramps' phases.
struct TrapezoidRamps {
    double t_in_s, t_out_s, needed_mm;
};

TrapezoidRamps trapezoid_ramps(double v_in, double vp, double v_out, double a) {
    TrapezoidRamps r;
    r.t_in_s = std::fabs(vp - v_in) / a;
    r.t_out_s = std::fabs(v_out - vp) / a;
    r.needed_mm = (v_in + vp) / 2 * r.t_in_s + (vp + v_out) / 2 * r.t_out_s;
    return r;
}

// build_profile_into() without a jerk limit: the same decisions on the same values (the peak
// at the cap, at the larger end speed, or where the two ramps meet), each ramp's time and
// length computed once instead of in every needed() and again in ramp().
void build_trapezoid_into(Profile1D& prof, double length, double v_in, double v_out, double vcap,
                          double a) {
    const double lo = std::max(v_in, v_out);
    double vpeak = vcap;
    TrapezoidRamps r;
    if (vpeak <= lo) {
        vpeak = lo;
        r = trapezoid_ramps(v_in, vpeak, v_out, a);
    } else if ((r = trapezoid_ramps(v_in, vpeak, v_out, a)).needed_mm > length) {
        vpeak = std::sqrt((2 * a * length + v_in * v_in + v_out * v_out) / 2);
        vpeak = std::clamp(vpeak, lo, vcap);
        r = trapezoid_ramps(v_in, vpeak, v_out, a);
    }
    PhaseWriter w(prof);
    w.start(v_in);
    w.ramp_unlimited(v_in, vpeak, a, r.t_in_s);
    double cruise_mm = length - r.needed_mm;
    if (vpeak > 0 && cruise_mm > 0) w.cruise(cruise_mm / vpeak);
    w.ramp_unlimited(vpeak, v_out, a, r.t_out_s);
    prof.duration_s = w.time();
    prof.peak_v_mm_s = vpeak;
}

}  // namespace

PathState Profile1D::at(double t_s) const noexcept {
    if (count == 0) return {};
    t_s = std::clamp(t_s, 0.0, duration_s);
    int i = count - 1;
    while (i > 0 && phases[i].t0_s > t_s) --i;
    const ProfilePhase& ph = phases[i];
    double dt = t_s - ph.t0_s;
    PathState st;
    st.s_mm =
        ph.s0_mm + ph.v0_mm_s * dt + ph.a0_mm_s2 * dt * dt / 2 + ph.j_mm_s3 * dt * dt * dt / 6;
    st.v_mm_s = std::max(0.0, ph.v0_mm_s + ph.a0_mm_s2 * dt + ph.j_mm_s3 * dt * dt / 2);
    st.a_mm_s2 = ph.a0_mm_s2 + ph.j_mm_s3 * dt;
    st.j_mm_s3 = ph.j_mm_s3;
    return st;
}

double ramp_time_s(double dv, const TangentLimits& lim) noexcept {
    double a = lim.acc_mm_s2;
    if (!jerk_limited(lim)) return dv / a;
    double j = lim.jerk_mm_s3;
    if (dv >= a * a / j) return dv / a + a / j;
    return 2 * std::sqrt(dv / j);
}

double ramp_distance_mm(double v0, double v1, const TangentLimits& lim) noexcept {
    // Both ramp shapes are point-symmetric in time, so the mean speed is (v0 + v1) / 2.
    return (v0 + v1) / 2 * ramp_time_s(std::fabs(v1 - v0), lim);
}

double detail::reachable_speed_jerk_limited_mm_s(double v0, double length,
                                                 const TangentLimits& lim) noexcept {
    double a = lim.acc_mm_s2;
    double j = lim.jerk_mm_s3;
    double c = a * a / j;  // speed change below which the ramp never reaches full acceleration
    // Jerk-limited branch: length = (2 v0 + x^2) x / sqrt(j) with x = sqrt(dv), a cubic
    // x^3 + p x - q = 0 with p >= 0, which has exactly one real root.
    double p = 2 * v0;
    double q = length * std::sqrt(j);
    double disc = std::sqrt(q * q / 4 + p * p * p / 27);
    double x = std::cbrt(q / 2 + disc) + std::cbrt(q / 2 - disc);
    for (int i = 0; i < 2; ++i) {  // Newton polish: Cardano loses digits when p dominates
        double f = x * x * x + p * x - q;
        x -= f / (3 * x * x + p);
    }
    double dv = x * x;
    if (dv <= c) return v0 + dv;
    // Acceleration-limited branch: 2 a length = (2 v0 + dv)(dv + c).
    double b = 2 * v0 + c;
    dv = (-b + std::sqrt(b * b - 4 * (2 * v0 * c - 2 * a * length))) / 2;
    return v0 + std::max(dv, c);
}

Profile1D build_profile(double length, double v_in, double v_out, double vcap,
                        const TangentLimits& lim) noexcept {
    Profile1D prof;
    build_profile_into(prof, length, v_in, v_out, vcap, lim);
    return prof;
}

void build_profile_into(Profile1D& prof, double length, double v_in, double v_out, double vcap,
                        const TangentLimits& lim) noexcept {
    if (!jerk_limited(lim))
        return build_trapezoid_into(prof, length, v_in, v_out, vcap, lim.acc_mm_s2);
    double lo = std::max(v_in, v_out);
    double vpeak = vcap;
    auto needed = [&](double vp) {
        return ramp_distance_mm(v_in, vp, lim) + ramp_distance_mm(vp, v_out, lim);
    };
    double needed_at_cap = 0;  // needed(vcap), when vpeak stays at the cap
    bool at_cap = false;
    if (vpeak <= lo) {
        vpeak = lo;
    } else if ((needed_at_cap = needed(vpeak)) > length) {
        vpeak = peak_speed_for_length(length, v_in, v_out, lo, vpeak, lim);
    } else {
        at_cap = true;
    }
    PhaseWriter w(prof);
    w.start(v_in);
    w.ramp(v_in, vpeak, lim);
    double cruise_mm = length - (at_cap ? needed_at_cap : needed(vpeak));
    if (vpeak > 0 && cruise_mm > 0) w.cruise(cruise_mm / vpeak);
    w.ramp(vpeak, v_out, lim);
    prof.duration_s = w.time();
    prof.peak_v_mm_s = vpeak;
}

}  // namespace motion
