#include "preview.hpp"

#include <cairo-svg.h>
#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <unordered_set>
#include <variant>

#include "interp/executor.hpp"
#include "interp/interpreter.hpp"

namespace cncrun {
namespace {

using Point = Preview::Point;
using Vec2 = std::array<double, 2>;

// ---- thinning -----------------------------------------------------------------------------

// Before the first thinning pass only samples within a micrometre of a chord are dropped:
// below what a G-code program can express, so the stored path is the followed path.
constexpr double kInitialToleranceMm = 1e-3;
// At most this many dropped samples are kept to check each new chord against, which bounds
// the work per sample; a longer straight stretch just keeps a vertex every this many samples.
constexpr std::size_t kChordWindow = 48;
// Thinning passes aim at this fraction of a pixel in the finest view, so they cannot be seen.
constexpr double kStoredTolerancePx = 0.1;
constexpr double kDrawnTolerancePx = 0.25;  // each view, in its own pixels, before drawing
constexpr std::size_t kMinStoredPoints = 16;

template <std::size_t N>
double distance(const std::array<double, N>& a, const std::array<double, N>& b) {
    double sum = 0;
    for (std::size_t k = 0; k < N; ++k) sum += (a[k] - b[k]) * (a[k] - b[k]);
    return std::sqrt(sum);
}

// Distance from p to the segment a–b (to the nearer end when p lies beyond one), so a path
// that doubles back along a chord is not mistaken for a point on it.
template <std::size_t N>
double distance_to_segment(const std::array<double, N>& p, const std::array<double, N>& a,
                           const std::array<double, N>& b) {
    double ab2 = 0, t = 0;
    for (std::size_t k = 0; k < N; ++k) {
        ab2 += (b[k] - a[k]) * (b[k] - a[k]);
        t += (p[k] - a[k]) * (b[k] - a[k]);
    }
    t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0.0;
    double sum = 0;
    for (std::size_t k = 0; k < N; ++k) {
        const double d = p[k] - (a[k] + t * (b[k] - a[k]));
        sum += d * d;
    }
    return std::sqrt(sum);
}

// Appends p to the polyline `out`, whose last vertex is the newest point so far and whose
// dropped points since the vertex before it are in `dropped`. The last vertex slides on to p
// when the chord from the vertex before reaches p within `tol` of every point it replaces;
// otherwise it stays and p becomes a new vertex. Every dropped point ends within tol of the
// final chord that spans it.
template <std::size_t N>
void append_thinned(std::vector<std::array<double, N>>& out,
                    std::vector<std::array<double, N>>& dropped, const std::array<double, N>& p,
                    double tol) {
    const std::size_t n = out.size();
    if (n >= 2 && dropped.size() < kChordWindow) {
        const auto& anchor = out[n - 2];
        bool covers = distance_to_segment(out[n - 1], anchor, p) <= tol;
        for (std::size_t i = 0; covers && i < dropped.size(); ++i)
            covers = distance_to_segment(dropped[i], anchor, p) <= tol;
        if (covers) {
            dropped.push_back(out[n - 1]);
            out[n - 1] = p;
            return;
        }
    }
    dropped.clear();
    out.push_back(p);
}

template <std::size_t N>
std::vector<std::array<double, N>> thinned(const std::vector<std::array<double, N>>& points,
                                           double tol) {
    std::vector<std::array<double, N>> out, dropped;
    out.reserve(points.size());
    for (const auto& p : points) append_thinned(out, dropped, p, tol);
    return out;
}

bool within(const std::vector<Point>& points, double tol) {
    return std::all_of(points.begin(), points.end(),
                       [&](const Point& p) { return distance(p, points.front()) <= tol; });
}

// ---- views --------------------------------------------------------------------------------

struct ViewSpec {
    View view;
    const char* caption;
    // Screen right and screen up as combinations of X, Y, Z.
    std::array<double, 3> right, up;
    int right_axis, up_axis;  // the model axes across and up; -1: not an orthographic view
};

// Third-angle projection: the right side view looks from +X, so +Y runs to the right. The
// isometric view looks from the front right, above (direction (-1, 1, -1)).
const double kR2 = 1 / std::sqrt(2.0), kR6 = 1 / std::sqrt(6.0);
const ViewSpec kViews[] = {
    {View::Top, "Top (XY)", {1, 0, 0}, {0, 1, 0}, 0, 1},
    {View::Front, "Front (XZ)", {1, 0, 0}, {0, 0, 1}, 0, 2},
    {View::Side, "Right (YZ)", {0, 1, 0}, {0, 0, 1}, 1, 2},
    {View::Iso, "Isometric", {kR2, kR2, 0}, {-kR6, kR6, 2 * kR6}, -1, -1},
};

Vec2 project(const ViewSpec& v, const Point& p) {
    return {v.right[0] * p[0] + v.right[1] * p[1] + v.right[2] * p[2],
            v.up[0] * p[0] + v.up[1] * p[1] + v.up[2] * p[2]};
}

// Panel insets: caption above, extents and scale bar below, the axis arrows at the left.
constexpr double kCaptionPx = 24, kFooterPx = 30, kLeftPx = 44, kRightPx = 14;
constexpr double kMarginPx = 12, kTitlePx = 48, kLegendPx = 36;

// Maps a view's model coordinates (mm) into its plot box, equal aspect, centred.
struct Fit {
    double px_per_mm = 1;
    Vec2 centre_mm{0, 0};
    PixelBox box{};
    Vec2 to_px(const Vec2& uv) const {
        return {box.x + box.w / 2 + (uv[0] - centre_mm[0]) * px_per_mm,
                box.y + box.h / 2 - (uv[1] - centre_mm[1]) * px_per_mm};
    }
};

Fit fit_view(const ViewSpec& v, const std::vector<Point>& corners_or_points) {
    Vec2 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    Vec2 hi{-lo[0], -lo[1]};
    for (const Point& p : corners_or_points) {
        const Vec2 uv = project(v, p);
        for (int k = 0; k < 2; ++k) {
            lo[k] = std::min(lo[k], uv[k]);
            hi[k] = std::max(hi[k], uv[k]);
        }
    }
    Fit f;
    f.box = plot_box(v.view);
    if (corners_or_points.empty()) return f;
    f.centre_mm = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2};
    // A path with no extent across the view is scaled by the other direction; a single point
    // (no extent at all) gets 1 mm across the panel.
    constexpr double kNone = 1e-9;
    const double span_u = hi[0] - lo[0], span_v = hi[1] - lo[1];
    if (std::max(span_u, span_v) <= kNone) {
        f.px_per_mm = std::min(f.box.w, f.box.h);
        return f;
    }
    const double inf = std::numeric_limits<double>::infinity();
    f.px_per_mm =
        std::min(span_u > kNone ? f.box.w / span_u : inf, span_v > kNone ? f.box.h / span_v : inf);
    return f;
}

// The eight corners of the extents box: enough to fit a view and find its scale.
std::vector<Point> box_corners(const Point& lo, const Point& hi) {
    std::vector<Point> out;
    for (int i = 0; i < 8; ++i)
        out.push_back({i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]});
    return out;
}

// ---- drawing ------------------------------------------------------------------------------

// What the samples span, and where they start and end; `any` is false for no sample at all.
struct Extents {
    Point lo, hi, start, end;
    bool any;
};

struct Rgb {
    double r, g, b;
};
constexpr Rgb kFeedColour{0x1f / 255.0, 0x5f / 255.0, 0xbf / 255.0};
constexpr Rgb kRapidColour{0xd6 / 255.0, 0x27 / 255.0, 0x28 / 255.0};
constexpr Rgb kStartColour{0x2c / 255.0, 0xa0 / 255.0, 0x2c / 255.0};
constexpr Rgb kEndColour{0, 0, 0};
constexpr Rgb kTextColour{0.2, 0.2, 0.2};
constexpr Rgb kFrameColour{0.7, 0.7, 0.7};
constexpr double kFeedWidthPx = 1.6, kRapidWidthPx = 1.2;
constexpr double kRapidDashPx[] = {5, 3};
// Long paths are stroked in pieces: cairo's stroker slows down on one path of very many
// self-crossing segments, and the joins between pieces cannot be seen.
constexpr std::size_t kStrokeChunk = 2000;

void set_colour(cairo_t* cr, const Rgb& c) {
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
}

enum class Align { Left, Centre, Right };

void text(cairo_t* cr, double x, double y, const std::string& s, double size,
          Align align = Align::Left, bool bold = false) {
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    const double dx = align == Align::Left     ? 0
                      : align == Align::Centre ? -e.x_advance / 2
                                               : -e.x_advance;
    cairo_move_to(cr, x + dx, y);
    cairo_show_text(cr, s.c_str());
}

void arrow(cairo_t* cr, Vec2 from, Vec2 to, const std::string& label) {
    cairo_move_to(cr, from[0], from[1]);
    cairo_line_to(cr, to[0], to[1]);
    cairo_stroke(cr);
    const double len = distance(from, to);
    if (len <= 0) return;
    const Vec2 d{(to[0] - from[0]) / len, (to[1] - from[1]) / len};
    const Vec2 n{-d[1], d[0]};
    cairo_move_to(cr, to[0], to[1]);
    cairo_line_to(cr, to[0] - 6 * d[0] + 3 * n[0], to[1] - 6 * d[1] + 3 * n[1]);
    cairo_line_to(cr, to[0] - 6 * d[0] - 3 * n[0], to[1] - 6 * d[1] - 3 * n[1]);
    cairo_close_path(cr);
    cairo_fill(cr);
    text(cr, to[0] + 9 * d[0] - 4, to[1] + 9 * d[1] + 4, label, 11);
}

// Screen directions of the model axes in a view (y down), for its arrows.
void axis_arrows(cairo_t* cr, const ViewSpec& v, const PixelBox& panel) {
    set_colour(cr, kTextColour);
    cairo_set_line_width(cr, 1);
    const Vec2 origin{panel.x + 14, panel.y + panel.h - (v.view == View::Iso ? 22 : 12)};
    const char* names[] = {"X", "Y", "Z"};
    for (int k = 0; k < 3; ++k) {
        Point unit{0, 0, 0};
        unit[k] = 1;
        const Vec2 uv = project(v, unit);
        if (std::hypot(uv[0], uv[1]) < 1e-9) continue;  // seen end on
        arrow(cr, origin, {origin[0] + 24 * uv[0], origin[1] - 24 * uv[1]}, names[k]);
    }
}

// The longest 1, 2 or 5 × 10^k mm that fits in `max_mm`.
double nice_length_mm(double max_mm) {
    const double decade = std::pow(10.0, std::floor(std::log10(max_mm)));
    for (double m : {5.0, 2.0, 1.0})
        if (m * decade <= max_mm) return m * decade;
    return decade;
}

void scale_bar(cairo_t* cr, const Fit& fit, const PixelBox& panel) {
    const double bar_mm = nice_length_mm(0.25 * fit.box.w / fit.px_per_mm);
    const double bar_px = bar_mm * fit.px_per_mm;
    const double x1 = panel.x + panel.w - kRightPx, x0 = x1 - bar_px;
    const double y = panel.y + panel.h - 10;
    set_colour(cr, kTextColour);
    cairo_set_line_width(cr, 1.5);
    cairo_move_to(cr, x0, y - 4);
    cairo_line_to(cr, x0, y);
    cairo_line_to(cr, x1, y);
    cairo_line_to(cr, x1, y - 4);
    cairo_stroke(cr);
    text(cr, x0 - 6, y, fmt::format("{:g} mm", bar_mm), 11, Align::Right);
}

std::string extents_text(const ViewSpec& v, const Point& lo, const Point& hi) {
    const auto one = [&](int k) {
        return fmt::format("{} {:.3f} … {:.3f}", "XYZ"[k], lo[k], hi[k]);
    };
    if (v.right_axis < 0) return fmt::format("{}   {}   {} mm", one(0), one(1), one(2));
    return fmt::format("{}   {} mm", one(v.right_axis), one(v.up_axis));
}

// One kind's strokes in one view, in pixels: a pen that moves (`pen_down` false) or draws.
struct PenStep {
    Vec2 to;
    bool pen_down;
};

// A segment's ends on a grid of `cell_px`, in either order: the key that finds a segment
// already drawn (a drilling program's 100 000 pecks down the same few lines).
struct SegmentKey {
    std::array<std::int32_t, 4> ends;
    bool operator==(const SegmentKey&) const = default;
};
struct SegmentKeyHash {
    std::size_t operator()(const SegmentKey& k) const {
        std::uint64_t h = 1469598103934665603ull;
        for (std::int32_t e : k.ends) h = (h ^ static_cast<std::uint32_t>(e)) * 1099511628211ull;
        return static_cast<std::size_t>(h);
    }
};

std::array<std::int32_t, 2> cell_of(const Vec2& p, double cell_px) {
    return {static_cast<std::int32_t>(std::lround(p[0] / cell_px)),
            static_cast<std::int32_t>(std::lround(p[1] / cell_px))};
}

// The stored runs of one kind, projected into a view's pixels, thinned there, and without
// the segments that are already drawn or shorter than the grid.
// Stops early, with more than `budget` steps, once that many are reached.
std::vector<PenStep> pen_steps(const std::vector<Preview::Run>& runs, MoveKind kind,
                               const ViewSpec& v, const Fit& fit, double tol_px,
                               std::size_t budget) {
    std::vector<PenStep> out;
    std::unordered_set<SegmentKey, SegmentKeyHash> drawn;
    std::vector<Vec2> px, dropped;
    for (const Preview::Run& r : runs) {
        if (out.size() > budget) break;
        if (r.kind != kind || r.points.size() < 2) continue;
        px.clear();
        dropped.clear();
        for (const Point& p : r.points)
            append_thinned(px, dropped, fit.to_px(project(v, p)), tol_px);
        bool pen_at_previous = false;
        for (std::size_t i = 0; i + 1 < px.size(); ++i) {
            const auto a = cell_of(px[i], tol_px), b = cell_of(px[i + 1], tol_px);
            const SegmentKey key{a < b ? std::array{a[0], a[1], b[0], b[1]}
                                       : std::array{b[0], b[1], a[0], a[1]}};
            if (a == b || !drawn.insert(key).second) {
                pen_at_previous = false;
                continue;
            }
            if (!pen_at_previous) out.push_back({px[i], false});
            out.push_back({px[i + 1], true});
            pen_at_previous = true;
        }
    }
    return out;
}

void stroke(cairo_t* cr, const std::vector<PenStep>& steps, MoveKind kind) {
    set_colour(cr, kind == MoveKind::Feed ? kFeedColour : kRapidColour);
    cairo_set_line_width(cr, kind == MoveKind::Feed ? kFeedWidthPx : kRapidWidthPx);
    if (kind == MoveKind::Rapid)
        cairo_set_dash(cr, kRapidDashPx, 2, 0);
    else
        cairo_set_dash(cr, nullptr, 0, 0);
    for (std::size_t i = 0; i < steps.size(); ++i) {
        if (!steps[i].pen_down)
            cairo_move_to(cr, steps[i].to[0], steps[i].to[1]);
        else if (i % kStrokeChunk == 0)  // a new piece carries on from the pen's place
            cairo_move_to(cr, steps[i - 1].to[0], steps[i - 1].to[1]);
        if (steps[i].pen_down) cairo_line_to(cr, steps[i].to[0], steps[i].to[1]);
        if (i % kStrokeChunk == kStrokeChunk - 1 || i + 1 == steps.size()) cairo_stroke(cr);
    }
    cairo_set_dash(cr, nullptr, 0, 0);
}

void markers(cairo_t* cr, const Fit& fit, const ViewSpec& v, const Point& start, const Point& end) {
    const Vec2 s = fit.to_px(project(v, start)), e = fit.to_px(project(v, end));
    cairo_set_line_width(cr, 1.5);
    set_colour(cr, kEndColour);
    cairo_rectangle(cr, e[0] - 4.5, e[1] - 4.5, 9, 9);
    cairo_stroke(cr);
    set_colour(cr, kStartColour);
    cairo_arc(cr, s[0], s[1], 4, 0, 2 * M_PI);
    cairo_fill(cr);
}

// What one picture shows: the runs thinned per view, and the fits.
struct ViewDrawing {
    const ViewSpec* spec;
    Fit fit;
    std::vector<PenStep> feeds, rapids;
    std::size_t vertices() const { return feeds.size() + rapids.size(); }
};

struct Scene {
    std::vector<ViewDrawing> views;
    double tol_px = kDrawnTolerancePx;
    std::size_t vertices = 0;
};

Scene build_scene(const Preview& p, const Extents& e, std::size_t max_vertices) {
    Scene scene;
    // An orthographic view's extents are exact from the samples' box; the isometric one needs
    // the points themselves (the box's corners would leave room around the path).
    std::vector<Point> points, corners;
    if (e.any) {
        for (const auto& r : p.runs())
            points.insert(points.end(), r.points.begin(), r.points.end());
        points.push_back(e.start);  // a lone sample is a run of one point: never drawn
        corners = box_corners(e.lo, e.hi);
    }
    for (const ViewSpec& spec : kViews)
        scene.views.push_back(
            {&spec, fit_view(spec, spec.right_axis < 0 ? points : corners), {}, {}});
    // Past kMaxTolerancePx the picture is a smear anyway: draw it rather than thin on.
    constexpr double kMaxTolerancePx = 64;
    for (;;) {
        const std::size_t budget = scene.tol_px >= kMaxTolerancePx
                                       ? std::numeric_limits<std::size_t>::max()
                                       : max_vertices;
        scene.vertices = 0;
        for (ViewDrawing& d : scene.views) {
            if (scene.vertices > budget) break;
            d.feeds = pen_steps(p.runs(), MoveKind::Feed, *d.spec, d.fit, scene.tol_px,
                                budget - scene.vertices);
            d.rapids = pen_steps(p.runs(), MoveKind::Rapid, *d.spec, d.fit, scene.tol_px,
                                 budget - std::min(budget, scene.vertices + d.feeds.size()));
            scene.vertices += d.vertices();
        }
        if (scene.vertices <= budget) return scene;
        scene.tol_px *= 2;
    }
}

void draw_panel(cairo_t* cr, const ViewDrawing& d, const Extents& e) {
    const ViewSpec& v = *d.spec;
    const PixelBox panel = panel_box(v.view);
    set_colour(cr, kFrameColour);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, panel.x + 0.5, panel.y + 0.5, panel.w - 1, panel.h - 1);
    cairo_stroke(cr);
    set_colour(cr, kTextColour);
    text(cr, panel.x + 8, panel.y + 17, v.caption, 13, Align::Left, true);
    axis_arrows(cr, v, panel);
    if (!e.any) {
        set_colour(cr, kTextColour);
        text(cr, panel.x + panel.w / 2, panel.y + panel.h / 2, "no motion", 14, Align::Centre);
        return;
    }
    set_colour(cr, kTextColour);
    text(cr, panel.x + 64, panel.y + panel.h - 10, extents_text(v, e.lo, e.hi), 11);
    if (v.right_axis >= 0) scale_bar(cr, d.fit, panel);
    cairo_save(cr);
    // The path may reach a pixel past its box (line width, thinning): keep it off the footer.
    cairo_rectangle(cr, panel.x + 1, panel.y + kCaptionPx - 4, panel.w - 2,
                    panel.h - kCaptionPx - kFooterPx + 8);
    cairo_clip(cr);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
    // Feeds over rapids: where a peck cycle retracts along the hole, the cut shows.
    stroke(cr, d.rapids, MoveKind::Rapid);
    stroke(cr, d.feeds, MoveKind::Feed);
    markers(cr, d.fit, v, e.start, e.end);
    cairo_restore(cr);
}

std::string title_text(const Preview& p, const PreviewCaption& c) {
    std::string head = c.program;
    if (!c.machine.empty()) head += " on " + c.machine;
    return fmt::format("{} — path {:.1f} mm (feed {:.1f}, rapid {:.1f}) — motion time {:.3f} s",
                       head, p.feed_length_mm() + p.rapid_length_mm(), p.feed_length_mm(),
                       p.rapid_length_mm(), c.motion_time_s);
}

void legend(cairo_t* cr, const Preview& p, const Scene& scene) {
    const double y = kPictureHeightPx - kLegendPx / 2 + 4;
    double x = kMarginPx + 4;
    const auto swatch = [&](MoveKind kind, const char* label) {
        set_colour(cr, kind == MoveKind::Feed ? kFeedColour : kRapidColour);
        cairo_set_line_width(cr, kind == MoveKind::Feed ? kFeedWidthPx : kRapidWidthPx);
        if (kind == MoveKind::Rapid) cairo_set_dash(cr, kRapidDashPx, 2, 0);
        cairo_move_to(cr, x, y - 4);
        cairo_line_to(cr, x + 32, y - 4);
        cairo_stroke(cr);
        cairo_set_dash(cr, nullptr, 0, 0);
        set_colour(cr, kTextColour);
        text(cr, x + 38, y, label, 12);
        x += 110;
    };
    swatch(MoveKind::Feed, "feed");
    swatch(MoveKind::Rapid, "rapid");
    set_colour(cr, kStartColour);
    cairo_arc(cr, x + 4, y - 4, 4, 0, 2 * M_PI);
    cairo_fill(cr);
    set_colour(cr, kTextColour);
    text(cr, x + 14, y, "start", 12);
    x += 70;
    set_colour(cr, kEndColour);
    cairo_set_line_width(cr, 1.5);
    cairo_rectangle(cr, x, y - 8.5, 9, 9);
    cairo_stroke(cr);
    set_colour(cr, kTextColour);
    text(cr, x + 14, y, "end", 12);
    const std::string note =
        fmt::format("{} samples, {} stored points (within {:.4f} mm), {} drawn vertices",
                    p.samples(), p.stored_points(), p.error_bound_mm(), scene.vertices);
    text(cr, kPictureWidthPx - kMarginPx - 4, y, note, 11, Align::Right);
}

struct CairoDeleter {
    void operator()(cairo_t* cr) const { cairo_destroy(cr); }
    void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
using Context = std::unique_ptr<cairo_t, CairoDeleter>;
using Surface = std::unique_ptr<cairo_surface_t, CairoDeleter>;

void check(cairo_status_t status, const std::string& path) {
    if (status != CAIRO_STATUS_SUCCESS)
        throw std::runtime_error(
            fmt::format("{}: cannot write the preview ({})", path, cairo_status_to_string(status)));
}

std::string lower_extension(const std::string& path) {
    const auto dot = path.rfind('.');
    const auto slash = path.rfind('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot);
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

// Each main-file line's moves from the canonical stream: their kinds, and their displacements
// for the lines that mix rapids and feeds.
class LineKinds : public interp::CanonSink {
  public:
    void emit(const interp::Canon& c) override {
        MoveKind kind = MoveKind::Other;
        Point end{};
        std::visit(
            [&](const auto& cmd) {
                using T = std::decay_t<decltype(cmd)>;
                if constexpr (std::is_same_v<T, interp::canon::Traverse> ||
                              std::is_same_v<T, interp::canon::FeedLine> ||
                              std::is_same_v<T, interp::canon::Arc>) {
                    kind = std::is_same_v<T, interp::canon::Traverse> ? MoveKind::Rapid
                                                                      : MoveKind::Feed;
                    end = {cmd.end_mm[0], cmd.end_mm[1], cmd.end_mm[2]};
                }
            },
            c.cmd);
        if (kind == MoveKind::Other) return;
        const Point delta{end[0] - last_end_[0], end[1] - last_end_[1], end[2] - last_end_[2]};
        last_end_ = end;
        if (c.loc.line < 0 || c.loc.file != main_file) return;
        if (c.loc.line != line_) {
            flush();
            line_ = c.loc.line;
        }
        // Every move is a stretch of its own, even next to one of the same kind: a peck
        // cycle's rapid up and back down would sum to a short hop the samples run past.
        moves_.push_back({kind, delta});
    }

    ProgramMoves take() {
        flush();
        return std::move(out_);
    }

    std::string main_file;

  private:
    // Ends a visit to a line: only mixed lines keep their moves, so a program of millions of
    // lines costs a byte per line. A line visited again (a loop) keeps its first visit's moves.
    void flush() {
        if (moves_.empty()) return;
        const auto has = [&](MoveKind k) {
            return std::any_of(moves_.begin(), moves_.end(),
                               [&](const LineMove& m) { return m.kind == k; });
        };
        const bool feeds = has(MoveKind::Feed), rapids = has(MoveKind::Rapid);
        const auto at = static_cast<std::size_t>(line_);
        auto& kinds = out_.line_kinds;
        if (kinds.size() <= at) kinds.resize(at + 1, MoveKind::Other);
        if (kinds[at] != MoveKind::Feed) kinds[at] = feeds ? MoveKind::Feed : MoveKind::Rapid;
        if (feeds && rapids) out_.mixed_lines.try_emplace(line_, moves_);
        moves_.clear();
    }

    Point last_end_{};
    int line_ = -1;
    std::vector<LineMove> moves_;  // of the current visit to line_
    ProgramMoves out_;
};

}  // namespace

ProgramMoves classify_lines(const std::string& program, const std::string& dialect) {
    LineKinds sink;
    sink.main_file = program;
    interp::Settings settings;
    interp::Executor exec(sink, interp::BackendConfig{}, settings);
    interp::InterpreterOptions options;
    options.main_m99_loops = false;  // a looping program would never end
    if (const interp::Dialect* d = interp::find_dialect(dialect)) options.dialect = d;
    interp::Interpreter in(exec, exec, options);
    in.open(program);
    while (in.step()) {
    }
    return sink.take();
}

std::string preview_path_error(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext == ".png" || ext == ".svg") return {};
    return fmt::format("{}: --preview writes PNG or SVG: the file name must end in .png or .svg",
                       path);
}

PixelBox panel_box(View view) {
    const double w = (kPictureWidthPx - 3 * kMarginPx) / 2;
    const double h = (kPictureHeightPx - kTitlePx - kLegendPx - kMarginPx) / 2;
    const bool right = view == View::Iso || view == View::Side;
    const bool lower = view == View::Front || view == View::Side;
    return {kMarginPx + (right ? w + kMarginPx : 0), kTitlePx + (lower ? h + kMarginPx : 0), w, h};
}

PixelBox plot_box(View view) {
    const PixelBox p = panel_box(view);
    return {p.x + kLeftPx, p.y + kCaptionPx, p.w - kLeftPx - kRightPx,
            p.h - kCaptionPx - kFooterPx};
}

Preview::Preview(ProgramMoves moves, PreviewLimits limits)
    : moves_(std::move(moves)),
      limits_(limits),
      tolerance_mm_(kInitialToleranceMm),
      error_bound_mm_(kInitialToleranceMm) {
    limits_.max_points = std::max(limits_.max_points, kMinStoredPoints);
}

// Within a mixed line a sample moves on to the next stretch once it has come within this of
// the current stretch's end or passed it, or is this much nearer the next stretch (a blended
// corner turns before the end): about a blend tolerance, less than a canned cycle's stretches.
constexpr double kStretchEndMm = 0.05;

MoveKind Preview::kind_of(int line, const Point& xyz_mm) {
    const auto mixed = moves_.mixed_lines.find(line);
    if (mixed != moves_.mixed_lines.end()) {
        const std::vector<LineMove>& stretches = mixed->second;
        const auto end_of = [&](const Point& from, std::size_t i) {
            const auto& d = stretches[i].delta_mm;
            return Point{from[0] + d[0], from[1] + d[1], from[2] + d[2]};
        };
        if (cursor_.line != line) {
            // The line starts where the machine was: the sample before this one.
            const Point start = samples_ > 0 ? end_ : xyz_mm;
            cursor_ = {line, 0, start, end_of(start, 0)};
        }
        while (cursor_.stretch + 1 < stretches.size()) {
            const Point& end = cursor_.end_mm;
            const auto& d = stretches[cursor_.stretch].delta_mm;
            const double len = std::hypot(d[0], d[1], d[2]);
            const double along = len > 0
                                     ? ((xyz_mm[0] - end[0]) * d[0] + (xyz_mm[1] - end[1]) * d[1] +
                                        (xyz_mm[2] - end[2]) * d[2]) /
                                           len
                                     : 0;
            const Point next_end = end_of(end, cursor_.stretch + 1);
            const bool reached = along >= -kStretchEndMm || distance(xyz_mm, end) <= kStretchEndMm;
            const bool nearer_next =
                distance_to_segment(xyz_mm, end, next_end) <
                distance_to_segment(xyz_mm, cursor_.start_mm, end) - kStretchEndMm;
            if (!reached && !nearer_next) break;
            ++cursor_.stretch;
            cursor_.start_mm = end;
            cursor_.end_mm = next_end;
        }
        return stretches[cursor_.stretch].kind;
    }
    cursor_.line = -1;
    const auto& kinds = moves_.line_kinds;
    const MoveKind kind = line >= 0 && static_cast<std::size_t>(line) < kinds.size()
                              ? kinds[static_cast<std::size_t>(line)]
                              : MoveKind::Other;
    if (kind != MoveKind::Other) return kind;
    return runs_.empty() ? MoveKind::Rapid : runs_.back().kind;
}

void Preview::add(const Point& xyz_mm, int line) {
    if (!std::isfinite(xyz_mm[0]) || !std::isfinite(xyz_mm[1]) || !std::isfinite(xyz_mm[2])) return;
    const MoveKind kind = kind_of(line, xyz_mm);
    if (samples_ == 0) {
        start_ = lo_ = hi_ = xyz_mm;
    } else {
        length_mm_[kind == MoveKind::Feed ? 1 : 0] += distance(end_, xyz_mm);
        for (int k = 0; k < 3; ++k) {
            lo_[k] = std::min(lo_[k], xyz_mm[k]);
            hi_[k] = std::max(hi_[k], xyz_mm[k]);
        }
    }
    ++samples_;
    if (runs_.empty() || runs_.back().kind != kind) {
        Run run{kind, {}};
        if (samples_ > 1) {
            run.points.push_back(end_);  // stay joined to the run before
            ++stored_;
        }
        runs_.push_back(std::move(run));
        pending_.clear();
    }
    end_ = xyz_mm;
    auto& points = runs_.back().points;
    const std::size_t before = points.size();
    append_thinned(points, pending_, xyz_mm, tolerance_mm_);
    stored_ += points.size() - before;
    if (stored_ > limits_.max_points) compact();
}

// Thins every run again with a coarser tolerance until at most half the point budget is used.
// Runs shorter than the tolerance are dropped (the open one is kept), and neighbours of the same
// kind merged, so the number of runs shrinks too.
void Preview::compact() {
    double finest_mm_per_px = std::numeric_limits<double>::infinity();
    for (const ViewSpec& v : kViews) {
        const Fit f = fit_view(v, box_corners(lo_, hi_));
        finest_mm_per_px = std::min(finest_mm_per_px, 1 / f.px_per_mm);
    }
    double tol = std::max(2 * tolerance_mm_, kStoredTolerancePx * finest_mm_per_px);
    for (;;) {
        std::vector<Run> kept;
        for (std::size_t i = 0; i < runs_.size(); ++i) {
            Run& r = runs_[i];
            const bool open = i + 1 == runs_.size();
            if (!open && within(r.points, tol)) continue;
            std::vector<Point> points = thinned(r.points, tol);
            if (!kept.empty() && kept.back().kind == r.kind) {
                auto& into = kept.back().points;
                into.insert(into.end(), points.begin() + 1, points.end());
            } else {
                kept.push_back(Run{r.kind, std::move(points)});
            }
        }
        runs_ = std::move(kept);
        stored_ = 0;
        for (const Run& r : runs_) stored_ += r.points.size();
        error_bound_mm_ += tol;
        tolerance_mm_ = tol;
        if (stored_ <= limits_.max_points / 2) break;
        tol *= 2;
    }
    pending_.clear();
}

void Preview::write(const std::string& path, const PreviewCaption& caption) const {
    if (std::string why = preview_path_error(path); !why.empty()) throw std::runtime_error(why);
    const bool svg = lower_extension(path) == ".svg";
    const Extents extents{lo_, hi_, start_, end_, samples_ > 0};
    const Scene scene = build_scene(
        *this, extents, svg ? limits_.max_svg_vertices : std::numeric_limits<std::size_t>::max());
    Surface surface(
        svg ? cairo_svg_surface_create(path.c_str(), kPictureWidthPx, kPictureHeightPx)
            : cairo_image_surface_create(CAIRO_FORMAT_RGB24, kPictureWidthPx, kPictureHeightPx));
    check(cairo_surface_status(surface.get()), path);
    if (svg) cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PX);
    Context cr(cairo_create(surface.get()));
    cairo_set_source_rgb(cr.get(), 1, 1, 1);
    cairo_paint(cr.get());
    set_colour(cr.get(), kTextColour);
    text(cr.get(), kMarginPx + 4, 30, title_text(*this, caption), 15, Align::Left, true);
    for (const ViewDrawing& d : scene.views) draw_panel(cr.get(), d, extents);
    legend(cr.get(), *this, scene);
    check(cairo_status(cr.get()), path);
    cr.reset();
    if (svg) {
        cairo_surface_finish(surface.get());
        check(cairo_surface_status(surface.get()), path);
    } else {
        check(cairo_surface_write_to_png(surface.get(), path.c_str()), path);
    }
}

}  // namespace cncrun
