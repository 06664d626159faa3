#include "program_gen.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace motion::test {
namespace {

using Vec3 = std::array<double, 3>;
constexpr double kPi = std::numbers::pi;

Vec3 normalized(Vec3 v) {
    double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    return {v[0] / n, v[1] / n, v[2] / n};
}

Vec3 random_unit(std::mt19937_64& rng) {
    std::normal_distribution<double> n(0, 1);
    return normalized({n(rng), n(rng), n(rng)});
}

// dir rotated by angle about a random axis perpendicular to it.
Vec3 turn(const Vec3& dir, double angle, std::mt19937_64& rng) {
    Vec3 r = random_unit(rng);
    double d = r[0] * dir[0] + r[1] * dir[1] + r[2] * dir[2];
    Vec3 perp = normalized({r[0] - d * dir[0], r[1] - d * dir[1], r[2] - d * dir[2]});
    double c = std::cos(angle), s = std::sin(angle);
    return {c * dir[0] + s * perp[0], c * dir[1] + s * perp[1], c * dir[2] + s * perp[2]};
}

struct Gen {
    std::mt19937_64& rng;
    Program prog;
    AxisArray pos{};
    Vec3 dir{1, 0, 0};
    std::uniform_real_distribution<double> u{0, 1};

    double uni(double a, double b) { return a + (b - a) * u(rng); }

    PathSegment base() {
        PathSegment s;
        s.rapid = u(rng) < 0.1;
        s.feed_mm_s = uni(5, 150);
        s.exact_stop = u(rng) < 0.05;
        static const double tols[] = {0, 0.002, 0.01, 0.05, 0.5};
        s.tolerance_mm = tols[std::uniform_int_distribution<int>(0, 4)(rng)];
        s.line = static_cast<std::int32_t>(prog.segs.size());
        return s;
    }

    void add_line(double length, const Vec3& d, bool rotary) {
        PathSegment s = base();
        s.end_mm = pos;
        for (int k = 0; k < 3; ++k) s.end_mm[k] += length * d[k];
        if (rotary) s.end_mm[3] += uni(-30, 30);
        prog.segs.push_back(s);
        pos = s.end_mm;
        dir = d;
    }

    void line(bool rotary) {
        double r = u(rng);
        Vec3 d = r < 0.15   ? dir
                 : r < 0.25 ? Vec3{-dir[0], -dir[1], -dir[2]}
                            : turn(dir, uni(0, kPi), rng);
        add_line(std::pow(10, uni(-3.5, 1.5)), d, rotary && u(rng) < 0.1);
    }

    // The current direction turned by `angle`, half the time within the XY plane (as most
    // programs' corners are).
    Vec3 turn_by(double angle) {
        if (u(rng) < 0.5 || std::hypot(dir[0], dir[1]) < 0.3) return turn(dir, angle, rng);
        const Vec3 flat = normalized({dir[0], dir[1], 0});
        const double a = std::atan2(flat[1], flat[0]) + (u(rng) < 0.5 ? angle : -angle);
        return {std::cos(a), std::sin(a), 0};
    }

    // A run of very short, nearly collinear moves (a finely sampled curve).
    void fine_chain() {
        int n = 20 + int(u(rng) * 60);
        double len = uni(0.005, 0.05);
        double bend = uni(0, 0.02);
        PathSegment proto = base();
        proto.rapid = false;
        for (int i = 0; i < n; ++i) {
            Vec3 d = turn(dir, bend, rng);
            add_line(len, d, false);
            PathSegment& s = prog.segs.back();
            s.feed_mm_s = proto.feed_mm_s;
            s.tolerance_mm = proto.tolerance_mm;
            s.rapid = false;
            s.exact_stop = false;
        }
    }

    void arc() {
        PathSegment s = base();
        s.kind = SegmentKind::Arc;
        bool tangent = u(rng) < 0.5 && std::hypot(dir[0], dir[1]) > 0.3;
        int plane = tangent ? 0 : std::uniform_int_distribution<int>(0, 2)(rng);
        static const int axes[3][3] = {{0, 1, 2}, {2, 0, 1}, {1, 2, 0}};
        int i = axes[plane][0], j = axes[plane][1], n = axes[plane][2];
        s.plane_first = i, s.plane_second = j, s.plane_normal = n;
        double r = std::pow(10, uni(-0.7, 1.3));
        bool ccw = u(rng) < 0.5;
        double cu, cv;
        if (tangent) {  // centre on the left (ccw) or right (cw) of the current direction
            double du = dir[0] / std::hypot(dir[0], dir[1]),
                   dv = dir[1] / std::hypot(dir[0], dir[1]);
            double side = ccw ? 1 : -1;
            cu = pos[i] - side * dv * r;
            cv = pos[j] + side * du * r;
        } else {
            double a = uni(0, 2 * kPi);
            cu = pos[i] + r * std::cos(a);
            cv = pos[j] + r * std::sin(a);
        }
        double th0 = std::atan2(pos[j] - cv, pos[i] - cu);
        double th1 = th0 + uni(-kPi, kPi);
        s.centre_mm = {cu, cv};
        s.end_mm = pos;
        s.end_mm[i] = cu + r * std::cos(th1);
        s.end_mm[j] = cv + r * std::sin(th1);
        if (tangent && std::fabs(dir[2]) > 1e-12) s.end_mm[n] = pos[n];  // planar only
        if (u(rng) < 0.4) s.end_mm[n] += uni(-5, 5);                     // helix
        int turns = u(rng) < 0.1 ? 2 : 1;
        s.turns = ccw ? turns : -turns;
        prog.segs.push_back(s);
        // continue along the end tangent
        Element e = make_arc(pos, s);
        EndDerivs ed = end_derivs(e);
        pos = s.end_mm;
        dir = normalized({ed.tangent[0], ed.tangent[1], ed.tangent[2]});
    }
};

}  // namespace

Program random_program(std::mt19937_64& rng, const GenOptions& opt) {
    Gen g{rng, {}, {}, random_unit(rng)};
    // Sometimes stay in the XY plane so that arcs can be tangent to lines.
    if (g.u(rng) < 0.5) g.dir = normalized({g.dir[0], g.dir[1], 0});
    while (int(g.prog.segs.size()) < opt.count) {
        double r = g.u(rng);
        if (opt.line_corners) {
            const bool short_line = g.u(rng) < 0.5;
            g.add_line(short_line ? g.uni(0.1, 0.8) : g.uni(2, 20),
                       g.turn_by(g.uni(kPi / 6, kPi * 13 / 18)), false);
            static const double tols[] = {0.002, 0.01, 0.05, 0.2};
            PathSegment& s = g.prog.segs.back();
            s.tolerance_mm = tols[std::uniform_int_distribution<int>(0, 3)(rng)];
            s.exact_stop = s.rapid = false;
            continue;
        }
        if (opt.arc_corners) {
            if (r < 0.3)
                g.line(false);
            else
                g.arc();
            static const double tols[] = {0.002, 0.01, 0.05, 0.5};
            PathSegment& s = g.prog.segs.back();
            s.tolerance_mm = tols[std::uniform_int_distribution<int>(0, 3)(rng)];
            s.exact_stop = false;
            continue;
        }
        if (r < 0.55)
            g.line(opt.rotary);
        else if (r < 0.85)
            g.arc();
        else
            g.fine_chain();
    }
    return g.prog;
}

AxisLimits random_limits(std::mt19937_64& rng, bool jerk) {
    std::uniform_real_distribution<double> u(0, 1);
    AxisLimits lim;
    for (int k = 0; k < kAxes; ++k) {
        lim.vel_mm_s[k] = 50 + 150 * u(rng);
        lim.acc_mm_s2[k] = 200 + 2800 * u(rng);
        lim.jerk_mm_s3[k] = jerk ? std::pow(10, 4 + 2 * u(rng)) : 0;
    }
    return lim;
}

std::vector<Element> programmed_elements(const Program& prog) {
    std::vector<Element> out;
    AxisArray pos = prog.start;
    for (const PathSegment& s : prog.segs) {
        out.push_back(s.kind == SegmentKind::Arc ? make_arc(pos, s) : make_line(pos, s.end_mm));
        pos = s.end_mm;
    }
    return out;
}

double distance_to(const Element& e, const AxisArray& p) {
    auto at = [&](double s) {
        CurvePoint cp;
        evaluate(e, s, cp);
        double d = 0;
        for (int k = 0; k < kAxes; ++k) d += (cp.p[k] - p[k]) * (cp.p[k] - p[k]);
        return std::sqrt(d);
    };
    if (e.kind == ElementKind::Line) {
        double along = 0;
        for (int k = 0; k < kAxes; ++k) along += (p[k] - e.origin[k]) * e.a[k];
        return at(std::clamp(along, 0.0, e.length_mm));
    }
    // Arc or helix: the nearest point is near a parameter where the angle matches the point's
    // angle about the centre (exactly so for a plain arc); refine around each such parameter.
    double pu = 0, pv = 0;
    for (int k = 0; k < kAxes; ++k) {
        pu += (p[k] - e.origin[k]) * e.a[k];
        pv += (p[k] - e.origin[k]) * e.b[k];
    }
    double th = std::atan2(pv, pu);
    double k1 = e.sweep_rad / e.length_mm;
    std::vector<double> candidates = {0, e.length_mm};
    for (int turn = -4; turn <= 4; ++turn) {
        double s = (th + 2 * kPi * turn - e.theta0_rad) / k1;
        if (s > 0 && s < e.length_mm) candidates.push_back(s);
    }
    double best = 1e300;
    const double g = (std::sqrt(5.0) - 1) / 2;
    for (double c : candidates) {
        double half = std::min(e.length_mm, 2.0);
        double lo = std::max(0.0, c - half), hi = std::min(e.length_mm, c + half);
        for (int i = 0; i < 80; ++i) {
            double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
            if (at(a) < at(b))
                hi = b;
            else
                lo = a;
        }
        best = std::min({best, at(c), at((lo + hi) / 2)});
    }
    return best;
}

namespace {

class Checker {
  public:
    Checker(const PlannerConfig& cfg, const Program& prog, double dt)
        : cfg_(cfg), prog_(prog), elems_(programmed_elements(prog)), dt_(dt) {}

    // Returns an empty string or the first problem with this sample.
    std::string check(long n, const MotionSample& s) {
        const AxisLimits& lim = cfg_.limits;
        const double rel = 1 + 1e-6;
        std::ostringstream why;
        for (int k = 0; k < kAxes; ++k) {
            if (!std::isfinite(s.pos_mm[k]) || !std::isfinite(s.vel_mm_s[k]) ||
                !std::isfinite(s.acc_mm_s2[k]) || !std::isfinite(s.jerk_mm_s3[k])) {
                why << "NaN/inf on axis " << k;
                break;
            }
            if (std::fabs(s.vel_mm_s[k]) > lim.vel_mm_s[k] * rel)
                why << "axis " << k << " velocity " << s.vel_mm_s[k] << " > " << lim.vel_mm_s[k];
            if (std::fabs(s.acc_mm_s2[k]) > lim.acc_mm_s2[k] * rel)
                why << "axis " << k << " acceleration " << s.acc_mm_s2[k] << " > "
                    << lim.acc_mm_s2[k];
            if (lim.jerk_mm_s3[k] > 0 && std::fabs(s.jerk_mm_s3[k]) > lim.jerk_mm_s3[k] * rel)
                why << "axis " << k << " jerk " << s.jerk_mm_s3[k] << " > " << lim.jerk_mm_s3[k];
            if (n >= 1) {
                double v_fd = (s.pos_mm[k] - p1_[k]) / dt_;
                if (std::fabs(v_fd) > lim.vel_mm_s[k] * rel + 1e-6)
                    why << "axis " << k << " sampled velocity " << v_fd;
                double j_fd = (s.acc_mm_s2[k] - a1_[k]) / dt_;
                if (lim.jerk_mm_s3[k] > 0 && std::fabs(j_fd) > lim.jerk_mm_s3[k] * rel + 1e-3)
                    why << "axis " << k << " sampled jerk " << j_fd << " > " << lim.jerk_mm_s3[k];
            }
            if (n >= 2) {
                double a_fd = (s.pos_mm[k] - 2 * p1_[k] + p2_[k]) / (dt_ * dt_);
                if (std::fabs(a_fd) > lim.acc_mm_s2[k] * rel + 1e-4)
                    why << "axis " << k << " sampled acceleration " << a_fd << " > "
                        << lim.acc_mm_s2[k];
            }
        }
        double dev = deviation(s);
        if (dev > 0) why << "path deviation exceeds the tolerance by " << dev << " mm";
        p2_ = p1_;
        p1_ = s.pos_mm;
        a1_ = s.acc_mm_s2;
        std::string w = why.str();
        if (!w.empty())
            w = "period " + std::to_string(n) + " line " + std::to_string(s.line) + ": " + w;
        return w;
    }

  private:
    // How far beyond the allowed tolerance the sample is from segment `line` (or, inside the
    // blend before it, from the previous segment; or, on a line, within the tolerance of the
    // corner at its end: the shift onto an offset corner, Planner's offset_corner, which may
    // take all of the line the corner at its start left); <= 0 when within.
    double deviation(const MotionSample& s) {
        std::size_t i = static_cast<std::size_t>(s.line);
        if (i >= elems_.size()) return 1e9;
        const Element& e = elems_[i];
        const double own = distance_to(e, s.pos_mm);
        double d = own;
        double allowed = 1e-7;
        if (d > allowed && i > 0) {
            d = std::min(d, distance_to(elems_[i - 1], s.pos_mm));
            allowed += prog_.segs[i - 1].tolerance_mm * (1 + 1e-6);
        }
        double excess = d - allowed;
        if (excess > 0 && e.kind == ElementKind::Line)
            excess = std::min(excess, own - 1e-7 - prog_.segs[i].tolerance_mm * (1 + 1e-6));
        return excess;
    }

    const PlannerConfig& cfg_;
    const Program& prog_;
    std::vector<Element> elems_;
    double dt_;
    AxisArray p1_{}, p2_{}, a1_{};
};

}  // namespace

PlayReport play(const PlannerConfig& cfg, const Program& prog, const Script& script,
                const PlayOptions& opt) {
    PlayReport rep;
    Planner planner(cfg, prog.start);
    SpscRing<PreparedSegment> ring(opt.ring_capacity);
    Sampler sampler(sampler_config(cfg), ring, prog.start);
    Checker checker(cfg, prog, opt.dt_s);
    std::size_t next_seg = 0;
    bool finished = false;
    PreparedSegment rec;
    bool have_rec = false;
    for (long n = 0; n < opt.max_periods; ++n) {
        // "Planner thread": keep the ring full.
        for (;;) {
            if (!have_rec) have_rec = planner.pop(rec);
            if (have_rec) {
                if (!ring.try_push(rec)) break;
                have_rec = false;
                continue;
            }
            if (next_seg < prog.segs.size()) {
                for (int i = 0; i < opt.segments_per_period && next_seg < prog.segs.size(); ++i)
                    planner.push(prog.segs[next_seg++]);
            } else if (!finished) {
                planner.finish();
                finished = true;
            } else {
                break;
            }
        }
        if (script) script(n, sampler);
        MotionSample s = sampler.advance(opt.dt_s);
        rep.samples.push_back(s);
        rep.last = s;
        rep.periods = n + 1;
        if (rep.violation.empty()) rep.violation = checker.check(n, s);
        const SamplerStatus& st = sampler.status();
        rep.starved |= st.starved;
        if (st.aborted) {
            rep.aborted = true;
            // hold still from here on
            for (int extra = 0; extra < 50; ++extra) {
                MotionSample h = sampler.advance(opt.dt_s);
                rep.samples.push_back(h);
                if (rep.violation.empty()) rep.violation = checker.check(++n, h);
                if (h.pos_mm != s.pos_mm && rep.violation.empty())
                    rep.violation = "moved after the abort completed";
            }
            break;
        }
        if (st.done && finished && next_seg == prog.segs.size() && !have_rec &&
            planner.ready() == 0 && ring.size() <= 1) {
            rep.done = true;
            break;
        }
    }
    return rep;
}

}  // namespace motion::test
