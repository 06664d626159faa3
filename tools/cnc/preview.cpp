#include "preview.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include "interp/executor.hpp"
#include "interp/interpreter.hpp"

namespace cncrun {
namespace {

constexpr double kMinStepMm = 0.1;  // samples closer than this to the last kept one are dropped
constexpr double kViewPx = 300;     // each view's square, pixels
constexpr double kPadPx = 12;       // inside a view, around the path
constexpr double kGapPx = 16;       // between views
constexpr double kTopPx = 40;       // title band
constexpr double kLegendPx = 36;    // legend band

class LineKinds : public interp::CanonSink {
  public:
    void emit(const interp::Canon& c) override {
        const MoveKind kind = std::visit(
            [](const auto& cmd) {
                using T = std::decay_t<decltype(cmd)>;
                if constexpr (std::is_same_v<T, interp::canon::Traverse>) return MoveKind::Rapid;
                if constexpr (std::is_same_v<T, interp::canon::FeedLine> ||
                              std::is_same_v<T, interp::canon::Arc>)
                    return MoveKind::Feed;
                return MoveKind::Other;
            },
            c.cmd);
        if (kind == MoveKind::Other || c.loc.line < 0 || c.loc.file != main_file) return;
        const auto line = static_cast<std::size_t>(c.loc.line);
        if (kinds.size() <= line) kinds.resize(line + 1, MoveKind::Other);
        if (kinds[line] != MoveKind::Feed) kinds[line] = kind;
    }
    std::string main_file;
    std::vector<MoveKind> kinds;
};

std::string xml_escape(const std::string& text) {
    std::string out;
    for (char c : text) {
        if (c == '<')
            out += "&lt;";
        else if (c == '>')
            out += "&gt;";
        else if (c == '&')
            out += "&amp;";
        else
            out += c;
    }
    return out;
}

double distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

}  // namespace

std::vector<MoveKind> classify_lines(const std::string& program, const std::string& dialect) {
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
    return sink.kinds;
}

void Preview::add(const std::array<double, 3>& xyz_mm, int line) {
    MoveKind kind = line >= 0 && static_cast<std::size_t>(line) < line_kinds_.size()
                        ? line_kinds_[static_cast<std::size_t>(line)]
                        : MoveKind::Other;
    if (kind == MoveKind::Other) kind = runs_.empty() ? MoveKind::Rapid : runs_.back().kind;
    if (runs_.empty() || runs_.back().kind != kind) {
        Run run{kind, {}};
        if (!runs_.empty()) run.points.push_back(runs_.back().points.back());  // stay joined
        runs_.push_back(std::move(run));
    }
    auto& points = runs_.back().points;
    if (points.empty() || distance(points.back(), xyz_mm) >= kMinStepMm) points.push_back(xyz_mm);
}

void Preview::write_svg(const std::string& path, const std::string& title) const {
    std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
    bool any = false;
    for (const Run& r : runs_)
        for (const auto& p : r.points) {
            for (int k = 0; k < 3; ++k) {
                lo[k] = any ? std::min(lo[k], p[k]) : p[k];
                hi[k] = any ? std::max(hi[k], p[k]) : p[k];
            }
            any = true;
        }
    const double span_mm = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1.0});
    const double px_per_mm = (kViewPx - 2 * kPadPx) / span_mm;  // one scale for all views

    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "w"),
                                                         &std::fclose);
    if (!file) throw std::runtime_error(fmt::format("{}: cannot open for writing", path));
    std::FILE* f = file.get();
    const double width = 3 * kViewPx + 4 * kGapPx, height = kTopPx + kViewPx + kLegendPx;
    fmt::print(f,
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" "
               "viewBox=\"0 0 {0} {1}\" font-family=\"sans-serif\" font-size=\"13\">\n"
               "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
               "<text x=\"{2}\" y=\"24\" font-size=\"15\">{3}</text>\n",
               width, height, kGapPx, xml_escape(title));

    struct View {
        const char* name;
        int u, v;  // axis indices drawn right and up
    };
    const View views[] = {{"XY (top)", 0, 1}, {"XZ (front)", 0, 2}, {"YZ (side)", 1, 2}};
    for (int i = 0; i < 3; ++i) {
        const View& view = views[i];
        const double ox = kGapPx + i * (kViewPx + kGapPx), oy = kTopPx;
        fmt::print(f,
                   "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" "
                   "stroke=\"#999\"/>\n<text x=\"{}\" y=\"{}\" fill=\"#555\">{}</text>\n",
                   ox, oy, kViewPx, kViewPx, ox + 6, oy + 16, view.name);
        for (const Run& r : runs_) {
            if (r.points.size() < 2) continue;
            fmt::print(f, "<polyline class=\"{}\" fill=\"none\" stroke=\"{}\" {}points=\"",
                       r.kind == MoveKind::Feed ? "feed" : "rapid",
                       r.kind == MoveKind::Feed ? "#1f5fbf" : "#d62728",
                       r.kind == MoveKind::Feed ? "stroke-width=\"1.5\" "
                                                : "stroke-width=\"1\" stroke-dasharray=\"4 3\" ");
            for (const auto& p : r.points)
                fmt::print(f, "{:.2f},{:.2f} ", ox + kPadPx + (p[view.u] - lo[view.u]) * px_per_mm,
                           oy + kViewPx - kPadPx - (p[view.v] - lo[view.v]) * px_per_mm);
            fmt::print(f, "\"/>\n");
        }
    }
    const double ly = kTopPx + kViewPx + 24;
    fmt::print(f,
               "<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"#1f5fbf\" "
               "stroke-width=\"1.5\"/><text x=\"{3}\" y=\"{4}\">feed</text>\n"
               "<line x1=\"{5}\" y1=\"{1}\" x2=\"{6}\" y2=\"{1}\" stroke=\"#d62728\" "
               "stroke-dasharray=\"4 3\"/><text x=\"{7}\" y=\"{4}\">rapid</text>\n"
               "<text x=\"{8}\" y=\"{4}\" fill=\"#555\">scale: {9:.3g} mm across a view</text>\n"
               "</svg>\n",
               kGapPx, ly - 4, kGapPx + 30, kGapPx + 36, ly, kGapPx + 90, kGapPx + 120,
               kGapPx + 126, kGapPx + 200, span_mm);
}

}  // namespace cncrun
