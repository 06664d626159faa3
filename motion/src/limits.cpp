#include "motion/limits.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace motion {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Share of an axis's acceleration that centripetal acceleration may take; the rest is left
// for speeding up and slowing down on curves. Blends are short, so their speed barely changes
// inside them and almost all of it goes to turning.
constexpr double kCentripetalShareArc = 0.8;
// Without a jerk limit speed changes on an arc are cheap (no ramp to build up), so turning gets
// more: 0.95 leaves sqrt(1 - 0.95^2) = 31 % for the tangential part at the cap (in quadrature).
// On tangent_arcs.ngc (radii 0.5-1.5 mm at F2400) 33.40 s at 0.8, 31.91 s at 0.95.
constexpr double kCentripetalShareArcNoJerk = 0.95;
constexpr double kCentripetalShareBlend = 0.95;
// Shares of the jerk budget for the v^3 p''' and 3 v a p'' terms of curved elements.
constexpr double kJerkCubicShareArc = 0.4;
constexpr double kJerkCrossShareArc = 0.3;
// Blends are short and mostly taken at constant speed: turning gets more of the jerk there.
constexpr double kJerkCubicShareBlend = 0.7;
constexpr double kJerkCrossShareBlend = 0.15;

// The loops below run over ElementBounds::axes only: every other axis has zero bounds and would
// add nothing to any minimum.

bool is_arc(const Element& e) {
    return e.kind == ElementKind::Arc;
}

double speed_cap(const Element& e, const ElementBounds& b, const AxisLimits& lim, double feed,
                 const LimitShares& share) {
    auto jerk = [&] {  // asked only for arcs: it reads all nine axes
        return std::any_of(lim.jerk_mm_s3.begin(), lim.jerk_mm_s3.end(),
                           [](double j) { return j > 0; });
    };
    double blend = share.blend_centripetal > 0 ? share.blend_centripetal : kCentripetalShareBlend;
    double centripetal = !is_arc(e) ? blend
                         : jerk()   ? kCentripetalShareArc
                                    : kCentripetalShareArcNoJerk;
    double cubic = is_arc(e) ? kJerkCubicShareArc : kJerkCubicShareBlend;
    // Smallest allowed v, v^2 and v^3 over the axes first, then one root of each.
    double v1 = feed > 0 ? feed : kInf, v2 = kInf, v3 = kInf;
    for (int i = 0; i < b.axis_count; ++i) {
        const int k = b.axes[i];
        if (b.g1[k] > 0) v1 = std::min(v1, lim.vel_mm_s[k] / b.g1[k]);
        if (b.g2[k] > 0) v2 = std::min(v2, centripetal * share.acc * lim.acc_mm_s2[k] / b.g2[k]);
        if (b.g3[k] > 0 && lim.jerk_mm_s3[k] > 0)
            v3 = std::min(v3, cubic * share.jerk * lim.jerk_mm_s3[k] / b.g3[k]);
    }
    double v = v1;
    if (v2 < v * v) v = std::sqrt(v2);
    if (v3 < v * v * v) v = std::cbrt(v3);
    return v;
}

// Largest a with sqrt((a t)^2 + n^2) + a l <= m: the in-plane part of an arc's acceleration is
// a rotating vector, so tangential and centripetal parts add in quadrature, not linearly. The
// left side grows with a, so this is the root of (t^2 - l^2) a^2 + 2 m l a + n^2 - m^2 = 0 with
// m - a l >= 0, written in the form that stays exact for t = l and for l = 0; 0 when the
// centripetal part n alone uses up m.
double arc_axis_acc(double t, double l, double n, double m) {
    if (t == 0 && l == 0) return kInf;
    if (n >= m) return 0;
    return (m - n) * (m + n) / (m * l + std::sqrt(m * m * t * t - n * n * (t * t - l * l)));
}

double tangential_acc(const Element& e, const ElementBounds& b, const AxisLimits& lim, double v,
                      const LimitShares& share) {
    double a = kInf;
    for (int i = 0; i < b.axis_count; ++i) {
        const int k = b.axes[i];
        double m = share.acc * lim.acc_mm_s2[k];
        double n = v * v * b.g2[k];
        if (is_arc(e)) {
            a = std::min(a, arc_axis_acc(b.tangential_in_plane[k], b.linear[k], n, m));
        } else if (b.g1[k] > 0) {
            a = std::min(a, (m - n) / b.g1[k]);
        }
    }
    return a;
}

}  // namespace

ElementLimits element_limits(const Element& e, const ElementBounds& b, const AxisLimits& lim,
                             double feed, const LimitShares& share) noexcept {
    ElementLimits out;
    double v = speed_cap(e, b, lim, feed, share);
    double a = tangential_acc(e, b, lim, v, share);
    double j = kInf;
    for (int i = 0; i < b.axis_count; ++i) {
        const int k = b.axes[i];
        if (lim.jerk_mm_s3[k] <= 0) continue;
        double m = share.jerk * lim.jerk_mm_s3[k];
        double cross = is_arc(e) ? kJerkCrossShareArc : kJerkCrossShareBlend;
        if (b.g2[k] > 0) a = std::min(a, cross * m / (3 * v * b.g2[k]));
        if (b.g1[k] > 0) j = std::min(j, (m - 3 * v * a * b.g2[k] - v * v * v * b.g3[k]) / b.g1[k]);
    }
    out.vcap_mm_s = v;
    out.tangent.acc_mm_s2 = a;
    out.tangent.jerk_mm_s3 = std::isfinite(j) ? j : 0;
    return out;
}

double parabola_cut_for_speed_mm(const AxisArray& dt_turn, double v_mm_s, const AxisLimits& lim,
                                 const LimitShares& share) noexcept {
    double blend = share.blend_centripetal > 0 ? share.blend_centripetal : kCentripetalShareBlend;
    double worst = 0;  // max_k |dT_k| / (allowed acceleration of k)
    for (int k = 0; k < kAxes; ++k)
        worst = std::max(worst, std::fabs(dt_turn[k]) / (blend * share.acc * lim.acc_mm_s2[k]));
    return v_mm_s * v_mm_s * worst / 2;
}

double rate_cap(const ElementBounds& b, const AxisLimits& lim, double v, double a, double j,
                const LimitShares& share, double max_rate) noexcept {
    // r scales velocity by r, acceleration by r^2 and jerk by r^3: collect the smallest
    // allowed r, r^2 and r^3 first, then take one root of each.
    double r1 = max_rate, r2 = kInf, r3 = kInf;
    for (int i = 0; i < b.axis_count; ++i) {
        const int k = b.axes[i];
        if (b.g1[k] == 0 && b.g2[k] == 0) continue;
        double vk = v * b.g1[k];
        double ak = a * b.g1[k] + v * v * b.g2[k];
        if (vk > 0) r1 = std::min(r1, lim.vel_mm_s[k] / vk);
        if (ak > 0) r2 = std::min(r2, share.acc * lim.acc_mm_s2[k] / ak);
        if (lim.jerk_mm_s3[k] > 0) {
            double jk = j * b.g1[k] + 3 * v * a * b.g2[k] + v * v * v * b.g3[k];
            if (jk > 0) r3 = std::min(r3, share.jerk * lim.jerk_mm_s3[k] / jk);
        }
    }
    double r = r1;
    if (r2 < r * r) r = std::sqrt(r2);
    if (r3 < r * r * r) r = std::cbrt(r3);
    return std::max(r, 1.0);
}

}  // namespace motion
