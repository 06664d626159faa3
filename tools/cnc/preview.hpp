// `cnc run --preview FILE.png|FILE.svg`: a picture of the path the machine followed, for a
// machinist to read at a glance. Four panels in third-angle layout — top (XY) above front (XZ),
// right side (YZ) beside the front, an isometric view top right — each scaled to fill its own
// panel at equal aspect ratio, with axis arrows, extents and a scale bar in mm. Feed moves are
// solid blue, rapids dashed red; the start is a green dot, the end a black square. A title line
// names the program and gives the path length and motion time. See docs/preview.md.
//
// Memory and output stay bounded whatever the program's length: samples are thinned as they
// arrive (never moving the drawn path by more than error_bound_mm()), and each view is thinned
// again in pixels before drawing.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace cncrun {

enum class MoveKind : std::uint8_t { Other, Rapid, Feed };

// One move of a line that both rapids and feeds (a canned cycle), as the displacement from
// the move before: a work offset moves the whole line and changes none.
struct LineMove {
    MoveKind kind;
    std::array<double, 3> delta_mm;
};

struct ProgramMoves {
    std::vector<MoveKind> line_kinds;  // index = line number; a mixed line counts as feed
    std::unordered_map<int, std::vector<LineMove>> mixed_lines;  // lines with both kinds
};

// For each line of the main program, whether it moves at the rapid or the feed rate, from
// the interpreter's canonical stream. Throws interp::Error (`file:line:col: reason`) for a
// bad program.
ProgramMoves classify_lines(const std::string& program, const std::string& dialect);

// Empty when `path` ends in .png or .svg (any case); otherwise why --preview cannot write it,
// naming the file.
std::string preview_path_error(const std::string& path);

// Picture geometry, pixels (SVG user units), y down. Exposed so tests can find the panels.
inline constexpr int kPictureWidthPx = 1200;
inline constexpr int kPictureHeightPx = 980;
enum class View : std::uint8_t { Top, Front, Side, Iso };
struct PixelBox {
    double x, y, w, h;
};
PixelBox panel_box(View view);  // a panel's frame, including its caption and footer
PixelBox plot_box(View view);   // the part of a panel the path is scaled into

struct PreviewLimits {
    // Stored vertices, all runs together. Past this the stored path is thinned with a coarser
    // tolerance until at most half this remains (so thinning costs O(1) amortized per sample).
    std::size_t max_points = 400'000;
    // Vertices written to an SVG, all four views together (about 16 bytes each): past this
    // each view is thinned more coarsely. Bounds the SVG's size; a PNG's is bounded by its
    // pixels.
    std::size_t max_svg_vertices = 300'000;
};

struct PreviewCaption {
    std::string program;  // shown as given
    std::string machine;  // the config; may be empty
    double motion_time_s = 0;
};

class Preview {
  public:
    explicit Preview(ProgramMoves moves, PreviewLimits limits = {});
    explicit Preview(std::vector<MoveKind> line_kinds, PreviewLimits limits = {})
        : Preview(ProgramMoves{std::move(line_kinds), {}}, limits) {}
    // One sample of the commanded position (mm) and the program line it belongs to. A line
    // that is neither rapid nor feed (or unknown) continues the current kind; within a mixed
    // line the kind follows the line's stretches as the samples reach each one's end.
    void add(const std::array<double, 3>& xyz_mm, int line);
    // Writes a PNG or an SVG, chosen by the file's extension. Throws std::runtime_error naming
    // the file for another extension or when it cannot be written.
    void write(const std::string& path, const PreviewCaption& caption) const;

    std::size_t samples() const { return samples_; }
    std::size_t stored_points() const { return stored_; }
    // No sample is farther than this from the stored path: 1 µm until the point budget is
    // reached, then the sum of the coarser tolerances used.
    double error_bound_mm() const { return error_bound_mm_; }
    double feed_length_mm() const { return length_mm_[1]; }
    double rapid_length_mm() const { return length_mm_[0]; }

    using Point = std::array<double, 3>;
    struct Run {
        MoveKind kind;
        std::vector<Point> points;  // joined: a run starts where the one before ended
    };
    const std::vector<Run>& runs() const { return runs_; }

  private:
    void compact();
    MoveKind kind_of(int line, const Point& xyz_mm);

    // Where the samples are in a mixed line: its stretch, and where that stretch starts and
    // ends.
    struct MixedCursor {
        int line = -1;
        std::size_t stretch = 0;
        Point start_mm{}, end_mm{};
    };

    ProgramMoves moves_;
    MixedCursor cursor_;
    PreviewLimits limits_;
    std::vector<Run> runs_;
    // Samples since the last stored vertex of the open run, all within tolerance_mm_ of the
    // chord from that vertex to the newest sample (the open run's last point).
    std::vector<Point> pending_;
    double tolerance_mm_;
    double error_bound_mm_;
    std::size_t samples_ = 0;
    std::size_t stored_ = 0;
    std::array<double, 2> length_mm_{0, 0};  // rapid, feed
    Point lo_{}, hi_{};                      // extents of every sample
    Point start_{}, end_{};
};

}  // namespace cncrun
