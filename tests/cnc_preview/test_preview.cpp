// The preview drawn from known paths: every expected figure follows from the path's geometry
// and the panel boxes (scale = the largest that fits the path's extents in the plot box).
#include <expat.h>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <regex>

#include "preview_test_util.hpp"

namespace {

using cncrun::MoveKind;
using cncrun::Preview;
using cncrun::PreviewCaption;
using cncrun::PreviewLimits;
using cncrun::View;
using Point = Preview::Point;
using namespace preview_test;

// Samples every `step_mm` from `from` (exclusive) to `to` (inclusive), as the servo loop would.
void move(Preview& p, const Point& from, const Point& to, int line, double step_mm = 0.1) {
    const double len = std::hypot(to[0] - from[0], to[1] - from[1], to[2] - from[2]);
    const int n = std::max(1, static_cast<int>(std::ceil(len / step_mm)));
    for (int i = 1; i <= n; ++i) {
        const double t = static_cast<double>(i) / n;
        p.add({from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1]),
               from[2] + t * (to[2] - from[2])},
              line);
    }
}

// Line 1 rapids from Z10 down to the origin, line 2 feeds a 50 x 30 mm rectangle in the XY
// plane at Z0, line 3 rapids back up to Z10.
const std::vector<MoveKind> kSquareKinds{MoveKind::Other, MoveKind::Rapid, MoveKind::Feed,
                                         MoveKind::Rapid};
void square_path(Preview& p) {
    p.add({0, 0, 10}, 1);
    move(p, {0, 0, 10}, {0, 0, 0}, 1);
    move(p, {0, 0, 0}, {50, 0, 0}, 2);
    move(p, {50, 0, 0}, {50, 30, 0}, 2);
    move(p, {50, 30, 0}, {0, 30, 0}, 2);
    move(p, {0, 30, 0}, {0, 0, 0}, 2);
    move(p, {0, 0, 0}, {0, 0, 10}, 3);
}

// px per mm for a path of extents u_mm x v_mm in a view's plot box.
double scale(View v, double u_mm, double v_mm) {
    const cncrun::PixelBox b = cncrun::plot_box(v);
    return std::min(b.w / u_mm, b.h / v_mm);
}

constexpr int kLinePx = 3;  // stroke width and antialiasing, either side

class SquarePng : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        scratch_ = new ScratchDir;
        Preview p(kSquareKinds);
        square_path(p);
        p.write((scratch_->path() / "square.png").string(), PreviewCaption{"square.ngc", "", 1.5});
        png_ = new Png(scratch_->path() / "square.png");
    }
    static void TearDownTestSuite() {
        delete png_;
        delete scratch_;
    }
    static ScratchDir* scratch_;
    static Png* png_;
};
ScratchDir* SquarePng::scratch_ = nullptr;
Png* SquarePng::png_ = nullptr;

TEST_F(SquarePng, IsAValidPngOfThePictureSize) {
    ASSERT_EQ(png_->status(), CAIRO_STATUS_SUCCESS);
    EXPECT_EQ(png_->width(), cncrun::kPictureWidthPx);
    EXPECT_EQ(png_->height(), cncrun::kPictureHeightPx);
}

TEST_F(SquarePng, TopViewShowsTheRectangleScaledToFillItsPanel) {
    ASSERT_EQ(png_->status(), CAIRO_STATUS_SUCCESS);
    const auto box = cncrun::panel_box(View::Top);
    const PixelBounds blue = find_hue(*png_, box, Hue::Blue);
    const double s = scale(View::Top, 50, 30);
    EXPECT_NEAR(blue.width(), 50 * s, kLinePx);
    EXPECT_NEAR(blue.height(), 30 * s, kLinePx);  // equal aspect: the same scale both ways
    // The rapids are vertical: seen from above they are a point and draw nothing.
    EXPECT_EQ(find_hue(*png_, box, Hue::Red).count, 0);
    // The start (the origin) is the rectangle's lower left corner: Y runs up the page.
    const PixelBounds green = find_hue(*png_, box, Hue::Green);
    ASSERT_GT(green.count, 0);
    EXPECT_NEAR((green.x0 + green.x1) / 2.0, blue.x0, kLinePx);
    EXPECT_NEAR((green.y0 + green.y1) / 2.0, blue.y1, kLinePx);
}

TEST_F(SquarePng, FrontAndSideViewsShowTheRapidAboveTheFeedAtTheStart) {
    ASSERT_EQ(png_->status(), CAIRO_STATUS_SUCCESS);
    struct Case {
        View view;
        double u_mm;  // the rectangle's width across the view
    };
    for (const Case c : {Case{View::Front, 50}, Case{View::Side, 30}}) {
        SCOPED_TRACE(static_cast<int>(c.view));
        const auto box = cncrun::panel_box(c.view);
        const double s = scale(c.view, c.u_mm, 10);
        const PixelBounds blue = find_hue(*png_, box, Hue::Blue);
        const PixelBounds red = find_hue(*png_, box, Hue::Red);
        ASSERT_GT(blue.count, 0);
        ASSERT_GT(red.count, 0);
        EXPECT_NEAR(blue.width(), c.u_mm * s, kLinePx);
        EXPECT_LE(blue.height(), kLinePx);  // the rectangle is flat: one line seen edge on
        // The rapid runs 10 mm straight up from the rectangle's left end. Its top is under
        // the start and end markers (up to 5 px), its bottom may end in a dash gap (3 px).
        EXPECT_NEAR(red.x0, blue.x0, kLinePx);
        EXPECT_LE(red.width(), kLinePx);
        EXPECT_LT(red.y0, blue.y0);
        EXPECT_LE(red.height(), 10 * s + kLinePx);
        EXPECT_GE(red.height(), 10 * s - 5 - 3 - kLinePx);
    }
}

TEST_F(SquarePng, IsometricViewShowsTheRapidRisingFromTheStart) {
    ASSERT_EQ(png_->status(), CAIRO_STATUS_SUCCESS);
    const auto box = cncrun::panel_box(View::Iso);
    EXPECT_GT(find_hue(*png_, box, Hue::Blue).count, 0);
    const PixelBounds red = find_hue(*png_, box, Hue::Red);
    const PixelBounds green = find_hue(*png_, box, Hue::Green);
    ASSERT_GT(red.count, 0);
    ASSERT_GT(green.count, 0);
    // Z is straight up the page in the isometric view too: the rapid is a vertical line
    // hanging from the start (X0 Y0 Z10) down to the rectangle's corner.
    const double start_x = (green.x0 + green.x1) / 2.0, start_y = (green.y0 + green.y1) / 2.0;
    EXPECT_LE(red.width(), kLinePx);
    EXPECT_NEAR((red.x0 + red.x1) / 2.0, start_x, kLinePx);
    EXPECT_GE(red.y0, start_y - kLinePx);
    EXPECT_GT(red.y1, start_y + 20);
}

TEST_F(SquarePng, NothingOfThePathOutsideThePanels) {
    // The title and legend bands hold one feed and one rapid swatch each, left of x = 300.
    const cncrun::PixelBox right_of_legend{300, 0, cncrun::kPictureWidthPx - 300.0,
                                           cncrun::kPictureHeightPx};
    const auto top = cncrun::panel_box(View::Top);
    const cncrun::PixelBox title{0, 0, cncrun::kPictureWidthPx, top.y};
    EXPECT_EQ(find_hue(*png_, title, Hue::Blue).count, 0);
    EXPECT_EQ(find_hue(*png_, title, Hue::Red).count, 0);
    const auto side = cncrun::panel_box(View::Side);
    const cncrun::PixelBox legend{right_of_legend.x, side.y + side.h, right_of_legend.w,
                                  cncrun::kPictureHeightPx - side.y - side.h};
    EXPECT_EQ(find_hue(*png_, legend, Hue::Blue).count, 0);
}

TEST(PreviewArcs, CircleIsDrawnRoundWithoutVisibleFacets) {
    // A full circle of radius 20 mm sampled every 0.02 mm (F1200 at 1 kHz). Seen from above,
    // every blue pixel lies on the circle of 20 mm at the panel's scale, within the stroke's
    // half width and antialiasing: facets or a lost arc would leave pixels off it.
    Preview p({MoveKind::Other, MoveKind::Feed});
    constexpr double kRadiusMm = 20;
    const int n = static_cast<int>(2 * M_PI * kRadiusMm / 0.02);
    for (int i = 0; i <= n; ++i) {
        const double a = 2 * M_PI * i / n;
        p.add({kRadiusMm * std::cos(a), kRadiusMm * std::sin(a), 0}, 1);
    }
    ScratchDir dir;
    p.write((dir.path() / "circle.png").string(), {});
    const Png png(dir.path() / "circle.png");
    ASSERT_EQ(png.status(), CAIRO_STATUS_SUCCESS);
    const auto plot = cncrun::plot_box(View::Top);
    const double radius_px = kRadiusMm * scale(View::Top, 2 * kRadiusMm, 2 * kRadiusMm);
    const double cx = plot.x + plot.w / 2, cy = plot.y + plot.h / 2;
    const auto box = cncrun::panel_box(View::Top);
    int blue = 0;
    double worst = 0;
    for (int y = static_cast<int>(box.y); y < static_cast<int>(box.y + box.h); ++y)
        for (int x = static_cast<int>(box.x); x < static_cast<int>(box.x + box.w); ++x) {
            if (hue(png.rgb(x, y)) != Hue::Blue) continue;
            ++blue;
            // Pixel centres: (x + 0.5, y + 0.5).
            const double r = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
            worst = std::max(worst, std::abs(r - radius_px));
        }
    EXPECT_LE(worst, 1.5);
    // About two pixels of stroke all the way round.
    EXPECT_GT(blue, 2 * M_PI * radius_px * 1.5);
}

TEST(PreviewLengths, FeedAndRapidLengthsFromTheSamples) {
    Preview p(kSquareKinds);
    square_path(p);
    EXPECT_NEAR(p.feed_length_mm(), 2 * (50 + 30), 1e-9);
    EXPECT_NEAR(p.rapid_length_mm(), 10 + 10, 1e-9);
}

TEST(PreviewKinds, LinesWithoutMotionContinueTheCurrentKind) {
    // Line 4 (say an M3) and line 99 (past the table) carry no kind of their own.
    Preview p({MoveKind::Other, MoveKind::Rapid, MoveKind::Feed, MoveKind::Other, MoveKind::Other});
    p.add({0, 0, 0}, 2);
    move(p, {0, 0, 0}, {10, 0, 0}, 2);
    move(p, {10, 0, 0}, {10, 5, 0}, 4);
    move(p, {10, 5, 0}, {10, 5, 3}, 99);
    move(p, {10, 5, 3}, {0, 5, 3}, 1);
    EXPECT_NEAR(p.feed_length_mm(), 10 + 5 + 3, 1e-9);
    EXPECT_NEAR(p.rapid_length_mm(), 10, 1e-9);
    ASSERT_EQ(p.runs().size(), 2u);
    EXPECT_EQ(p.runs()[0].kind, MoveKind::Feed);
    EXPECT_EQ(p.runs()[1].kind, MoveKind::Rapid);
    // Joined: the rapid starts where the feed ended.
    EXPECT_EQ(p.runs()[1].points.front(), (Point{10, 5, 3}));
}

TEST(PreviewKinds, ClassifiesProgramLinesFromTheCanonicalStream) {
    ScratchDir dir;
    const auto path = (dir.path() / "kinds.ngc").string();
    std::ofstream(path) << "G90 G21 G17\nG0 X10\nG1 X20 F100\nG2 X30 I5 J0\nM3 S1000\nM30\n";
    const std::vector<MoveKind> kinds = cncrun::classify_lines(path, "ncstudio").line_kinds;
    ASSERT_GE(kinds.size(), 5u);
    EXPECT_EQ(kinds[1], MoveKind::Other);
    EXPECT_EQ(kinds[2], MoveKind::Rapid);
    EXPECT_EQ(kinds[3], MoveKind::Feed);
    EXPECT_EQ(kinds[4], MoveKind::Feed);
    if (kinds.size() > 5) {
        EXPECT_EQ(kinds[5], MoveKind::Other);
    }
}

// A G81 drilling cycle on two holes; each cycle line rapids over and down to R2, feeds to
// Z-5 and rapids back up to Z10 (G98). By hand: per hole 7 mm of feed, 10 + 8 + 15 mm of rapid.
class CannedCycle : public ::testing::TestWithParam<Point> {
  protected:
    void SetUp() override {
        const auto path = (dir_.path() / "g81.ngc").string();
        std::ofstream(path)
            << "G90 G21 G17 G98\nG0 X0 Y0 Z10\nG81 X10 Y0 Z-5 R2 F100\nX20\nG80\nM30\n";
        moves_ = cncrun::classify_lines(path, "ncstudio");
    }
    ScratchDir dir_;
    cncrun::ProgramMoves moves_;
};

TEST_P(CannedCycle, RapidsAndFeedsWithinACycleLineAreToldApart) {
    ASSERT_EQ(moves_.mixed_lines.count(3), 1u);
    ASSERT_EQ(moves_.mixed_lines.count(4), 1u);
    // The machine's positions are the program's plus a work offset (the parameter): the
    // stretches are displacements, so the offset changes nothing.
    const Point o = GetParam();
    const auto at = [&](double x, double y, double z) {
        return Point{x + o[0], y + o[1], z + o[2]};
    };
    Preview p(moves_);
    p.add(at(0, 0, 10), 2);
    Point here = at(0, 0, 10);
    for (int line : {3, 4}) {
        const double x = line == 3 ? 10 : 20;
        for (const Point& to : {at(x, 0, 10), at(x, 0, 2), at(x, 0, -5), at(x, 0, 10)}) {
            move(p, here, to, line);
            here = to;
        }
    }
    // One 0.1 mm sample step at each change of kind may fall either side.
    EXPECT_NEAR(p.feed_length_mm(), 2 * 7, 0.25);
    EXPECT_NEAR(p.rapid_length_mm(), 2 * (10 + 8 + 15), 0.25);
    std::vector<MoveKind> kinds;
    for (const auto& r : p.runs()) kinds.push_back(r.kind);
    EXPECT_EQ(kinds, (std::vector<MoveKind>{MoveKind::Rapid, MoveKind::Feed, MoveKind::Rapid,
                                            MoveKind::Feed, MoveKind::Rapid}));
}

INSTANTIATE_TEST_SUITE_P(Offsets, CannedCycle,
                         ::testing::Values(Point{0, 0, 0}, Point{100, -50, -20}));

TEST(PreviewKinds, BadProgramIsAnErrorNamingTheFile) {
    ScratchDir dir;
    const auto path = (dir.path() / "bad.ngc").string();
    std::ofstream(path) << "G0 X10\nG1 X#\nM30\n";
    try {
        cncrun::classify_lines(path, "ncstudio");
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("bad.ngc:2"), std::string::npos) << e.what();
    }
}

TEST(PreviewFileName, OnlyPngAndSvgInAnyCase) {
    for (const char* ok : {"a.png", "a.svg", "dir/b.PNG", "c.Svg"})
        EXPECT_EQ(cncrun::preview_path_error(ok), "") << ok;
    for (const char* bad : {"a.bmp", "a", "a.png.txt", "dir.png/a", "png", ".svg.pdf"}) {
        const std::string why = cncrun::preview_path_error(bad);
        EXPECT_NE(why.find(bad), std::string::npos) << why;
        EXPECT_NE(why.find(".png or .svg"), std::string::npos) << why;
    }
}

TEST(PreviewFileName, WriteRefusesAnotherExtensionAndWritesNothing) {
    ScratchDir dir;
    Preview p(kSquareKinds);
    square_path(p);
    const auto path = (dir.path() / "out.jpg").string();
    try {
        p.write(path, {});
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(path));
}

TEST(PreviewFileName, UnwritablePathIsAnErrorNamingTheFile) {
    ScratchDir dir;
    Preview p(kSquareKinds);
    square_path(p);
    for (const char* name : {"no/such/dir/p.png", "no/such/dir/p.svg"}) {
        const auto path = (dir.path() / name).string();
        try {
            p.write(path, {});
            ADD_FAILURE() << "no error for " << name;
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        }
    }
}

// Collects the stroke styles of an SVG while expat checks that it is well-formed XML.
struct SvgScan {
    std::string root;
    std::string width, height;
    int elements = 0;
    std::vector<std::string> styles;    // of the stroked elements (not the glyphs)
    std::vector<std::size_t> vertices;  // M and L commands of each, in the same order
};

void on_start(void* data, const XML_Char* name, const XML_Char** attrs) {
    auto* scan = static_cast<SvgScan*>(data);
    if (scan->elements++ == 0) scan->root = name;
    std::string style, d;
    for (int i = 0; attrs[i]; i += 2) {
        const std::string key = attrs[i], value = attrs[i + 1];
        if (scan->elements == 1 && key == "width") scan->width = value;
        if (scan->elements == 1 && key == "height") scan->height = value;
        if (key == "style") style = value;
        if (key == "d") d = value;
    }
    if (style.find("stroke:rgb") == std::string::npos) return;  // not a glyph (stroke:none)
    scan->styles.push_back(style);
    scan->vertices.push_back(
        std::count_if(d.begin(), d.end(), [](char c) { return c == 'M' || c == 'L'; }));
}

// Parses the whole document; returns expat's error, or "" when the SVG is well-formed.
std::string parse_svg(const std::string& text, SvgScan& scan) {
    std::unique_ptr<XML_ParserStruct, void (*)(XML_Parser)> parser(XML_ParserCreate(nullptr),
                                                                   &XML_ParserFree);
    XML_SetUserData(parser.get(), &scan);
    XML_SetStartElementHandler(parser.get(), &on_start);
    if (XML_Parse(parser.get(), text.data(), static_cast<int>(text.size()), 1) == XML_STATUS_ERROR)
        return fmt::format("line {}: {}", XML_GetCurrentLineNumber(parser.get()),
                           XML_ErrorString(XML_GetErrorCode(parser.get())));
    return "";
}

enum class Stroke { Feed, Rapid, Other };
// From a cairo style: "stroke:rgb(12.156863%,37.254902%,74.901961%)".
Stroke stroke_of(const std::string& style) {
    static const std::regex rgb(R"(stroke:rgb\(([0-9.]+)%,([0-9.]+)%,([0-9.]+)%\))");
    std::smatch m;
    if (!std::regex_search(style, m, rgb)) return Stroke::Other;
    const auto channel = [&](int i) {
        return static_cast<std::uint32_t>(std::lround(std::stod(m[i]) * 2.55));
    };
    switch (hue(channel(1) << 16 | channel(2) << 8 | channel(3))) {
        case Hue::Blue:
            return Stroke::Feed;
        case Hue::Red:
            return Stroke::Rapid;
        default:
            return Stroke::Other;
    }
}

TEST(PreviewSvg, IsWellFormedWithDashedRapidsAndSolidFeeds) {
    ScratchDir dir;
    Preview p(kSquareKinds);
    square_path(p);
    const auto path = dir.path() / "square.svg";
    p.write(path.string(), PreviewCaption{"square <&> .ngc", "mill.ini", 1.5});
    SvgScan scan;
    ASSERT_EQ(parse_svg(slurp(path), scan), "");
    EXPECT_EQ(scan.root, "svg");
    EXPECT_EQ(std::stod(scan.width), cncrun::kPictureWidthPx) << scan.width;
    EXPECT_EQ(std::stod(scan.height), cncrun::kPictureHeightPx) << scan.height;
    int feeds = 0, rapids = 0;
    for (const std::string& style : scan.styles) {
        const Stroke s = stroke_of(style);
        const bool dashed = style.find("stroke-dasharray") != std::string::npos;
        if (s == Stroke::Feed) {
            ++feeds;
            EXPECT_FALSE(dashed) << style;
        }
        if (s == Stroke::Rapid) {
            ++rapids;
            EXPECT_TRUE(dashed) << style;
        }
    }
    // Four views of the feed and the legend's swatch; the rapids show in three views.
    EXPECT_GE(feeds, 5);
    EXPECT_GE(rapids, 4);
}

TEST(PreviewEdgeCases, EmptyProgramDrawsEmptyPanels) {
    ScratchDir dir;
    const Preview p(cncrun::ProgramMoves{});
    for (const char* name : {"empty.png", "empty.svg"})
        ASSERT_NO_THROW(p.write((dir.path() / name).string(), PreviewCaption{"empty.ngc", "", 0}));
    const Png png(dir.path() / "empty.png");
    ASSERT_EQ(png.status(), CAIRO_STATUS_SUCCESS);
    for (View v : {View::Top, View::Front, View::Side, View::Iso})
        for (Hue h : {Hue::Blue, Hue::Red, Hue::Green})
            EXPECT_EQ(find_hue(png, cncrun::panel_box(v), h).count, 0);
    SvgScan scan;
    EXPECT_EQ(parse_svg(slurp(dir.path() / "empty.svg"), scan), "");
}

TEST(PreviewEdgeCases, SinglePointIsMarkedAtEveryPanelsCentre) {
    ScratchDir dir;
    Preview p({MoveKind::Other, MoveKind::Feed});
    p.add({3, 4, 5}, 1);
    const auto path = dir.path() / "one.png";
    p.write(path.string(), {});
    const Png png(path);
    ASSERT_EQ(png.status(), CAIRO_STATUS_SUCCESS);
    for (View v : {View::Top, View::Front, View::Side, View::Iso}) {
        const auto plot = cncrun::plot_box(v);
        const PixelBounds green = find_hue(png, cncrun::panel_box(v), Hue::Green);
        ASSERT_GT(green.count, 0);
        EXPECT_NEAR((green.x0 + green.x1) / 2.0, plot.x + plot.w / 2, 2);
        EXPECT_NEAR((green.y0 + green.y1) / 2.0, plot.y + plot.h / 2, 2);
        EXPECT_EQ(find_hue(png, cncrun::panel_box(v), Hue::Blue).count, 0);
    }
}

TEST(PreviewEdgeCases, NonFiniteSamplesAreIgnored) {
    Preview p(kSquareKinds);
    p.add({0, 0, 0}, 2);
    p.add({NAN, 0, 0}, 2);
    p.add({1, 0, INFINITY}, 2);
    p.add({1, 0, 0}, 2);
    EXPECT_EQ(p.samples(), 2u);
    EXPECT_NEAR(p.feed_length_mm(), 1, 1e-12);
}

// Distance from p to the polyline through `points`.
double distance_to_polyline(const Point& p, const std::vector<Point>& points) {
    double best = INFINITY;
    for (std::size_t i = 0; i + 1 < points.size(); ++i) {
        const Point& a = points[i];
        const Point& b = points[i + 1];
        double ab2 = 0, t = 0;
        for (int k = 0; k < 3; ++k) {
            ab2 += (b[k] - a[k]) * (b[k] - a[k]);
            t += (p[k] - a[k]) * (b[k] - a[k]);
        }
        t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0.0;
        best = std::min(best,
                        std::hypot(p[0] - a[0] - t * (b[0] - a[0]), p[1] - a[1] - t * (b[1] - a[1]),
                                   p[2] - a[2] - t * (b[2] - a[2])));
    }
    return best;
}

// A wandering 3D curve: every sample turns a little, so no sample lies on a chord.
std::vector<Point> wandering_path(std::size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> turn(0, 0.2);
    std::vector<Point> out;
    Point p{0, 0, 0};
    double heading = 0, climb = 0;
    for (std::size_t i = 0; i < n; ++i) {
        heading += turn(rng);
        climb = std::clamp(climb + 0.3 * turn(rng), -0.5, 0.5);
        p = {p[0] + 0.05 * std::cos(heading), p[1] + 0.05 * std::sin(heading),
             p[2] + 0.05 * std::sin(climb)};
        out.push_back(p);
    }
    return out;
}

TEST(PreviewThinning, EverySampleStaysWithinTheBoundOfTheStoredPath) {
    const PreviewLimits limits{1000, 300'000};
    Preview p({MoveKind::Other, MoveKind::Feed}, limits);
    const std::vector<Point> path = wandering_path(20'000, 7);
    for (const Point& q : path) p.add(q, 1);
    ASSERT_EQ(p.runs().size(), 1u);
    EXPECT_LE(p.stored_points(), limits.max_points);
    EXPECT_GT(p.error_bound_mm(), 1e-3);  // it had to thin past the initial tolerance
    const auto& stored = p.runs()[0].points;
    EXPECT_EQ(stored.front(), path.front());
    EXPECT_EQ(stored.back(), path.back());
    double worst = 0;
    for (const Point& q : path) worst = std::max(worst, distance_to_polyline(q, stored));
    EXPECT_LE(worst, p.error_bound_mm());
    // The bound is not vacuous: it is small against the path's size (tens of mm).
    EXPECT_LT(p.error_bound_mm(), 1.0);
}

TEST(PreviewThinning, AlternatingKindsStayBoundedToo) {
    // A drilling-like program: 100 000 tiny feed/rapid pairs, each its own run.
    const PreviewLimits limits{2000, 300'000};
    Preview p({MoveKind::Other, MoveKind::Rapid, MoveKind::Feed}, limits);
    for (int i = 0; i < 100'000; ++i) {
        const double x = (i % 300) * 0.5, y = (i / 300) * 0.5;
        p.add({x, y, 1}, 1);
        p.add({x, y, 0}, 2);
    }
    EXPECT_LE(p.stored_points(), limits.max_points);
    EXPECT_NEAR(p.feed_length_mm(), 100'000, 1e-6);
}

TEST(PreviewThinning, SvgVerticesStayUnderTheCap) {
    // 20 000 holes on a 0.7 x 0.9 mm grid, drilled by a feed down and a rapid up and over:
    // far more distinct segments than the cap allows at a quarter pixel.
    const PreviewLimits limits{400'000, 5000};
    Preview p({MoveKind::Other, MoveKind::Rapid, MoveKind::Feed}, limits);
    for (int i = 0; i < 20'000; ++i) {
        const double x = (i % 150) * 0.7, y = (i / 150) * 0.9;
        p.add({x, y, 2}, 1);
        move(p, {x, y, 2}, {x, y, -1}, 2, 0.5);
    }
    ScratchDir dir;
    const auto path = dir.path() / "holes.svg";
    p.write(path.string(), {});
    SvgScan scan;
    ASSERT_EQ(parse_svg(slurp(path), scan), "");
    std::size_t path_vertices = 0;
    int rapids = 0;
    for (std::size_t i = 0; i < scan.styles.size(); ++i) {
        const Stroke s = stroke_of(scan.styles[i]);
        if (s != Stroke::Other) path_vertices += scan.vertices[i];
        rapids += s == Stroke::Rapid;
    }
    // The legend's two swatches (2 vertices each) come on top of the cap. Without the cap
    // this program draws about 120 000.
    EXPECT_LE(path_vertices, limits.max_svg_vertices + 4);
    EXPECT_GT(path_vertices, limits.max_svg_vertices / 10) << "thinned far past the cap";
    EXPECT_GE(rapids, 4);  // still drawn, in every view and the legend
}

TEST(PreviewThinning, StraightLinesAreNotStoredSampleBySample) {
    Preview p({MoveKind::Other, MoveKind::Feed});
    move(p, {0, 0, 0}, {100, 0, 0}, 1, 0.01);  // 10 000 collinear samples
    EXPECT_EQ(p.samples(), 10'000u);
    EXPECT_LT(p.stored_points(), 10'000u / 40);
}

// A 3D surfacing raster of 1M samples, 0.1 mm apart (F6000 sampled at 1 kHz): 1000 rows
// along X over a wavy surface. With the default limits the stored points, the SVG's size and
// the time to write both stay bounded.
TEST(PreviewHuge, MillionSampleSurfaceStaysBounded) {
    using Clock = std::chrono::steady_clock;
    ScratchDir dir;
    const PreviewLimits limits;
    Preview p({MoveKind::Other, MoveKind::Rapid, MoveKind::Feed});
    const auto t0 = Clock::now();
    constexpr int kRows = 1000, kPerRow = 1000;
    for (int row = 0; row < kRows; ++row) {
        const double y = row * 0.1;
        for (int i = 0; i < kPerRow; ++i) {
            const double x = (row % 2 ? kPerRow - 1 - i : i) * 0.1;
            p.add({x, y, 2 * std::sin(x / 7) * std::cos(y / 11)}, 2);
        }
    }
    const auto t1 = Clock::now();
    const auto png = dir.path() / "huge.png", svg = dir.path() / "huge.svg";
    p.write(png.string(), PreviewCaption{"surface.ngc", "", 1000});
    const auto t2 = Clock::now();
    p.write(svg.string(), PreviewCaption{"surface.ngc", "", 1000});
    const auto t3 = Clock::now();
    const auto s = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
    std::printf(
        "1M samples: add %.3f s, png %.3f s (%ju bytes), svg %.3f s (%ju bytes), "
        "%zu stored points, error bound %.4f mm\n",
        s(t0, t1), s(t1, t2), static_cast<std::uintmax_t>(fs::file_size(png)), s(t2, t3),
        static_cast<std::uintmax_t>(fs::file_size(svg)), p.stored_points(), p.error_bound_mm());
    EXPECT_EQ(p.samples(), 1'000'000u);
    EXPECT_LE(p.stored_points(), limits.max_points);
    // About 25 bytes per drawn vertex in cairo's SVG, plus the text's glyphs.
    EXPECT_LE(fs::file_size(svg), limits.max_svg_vertices * 25 + 500'000);
    const Png back(png);
    ASSERT_EQ(back.status(), CAIRO_STATUS_SUCCESS);
    // The raster covers the top view: 100 x 100 mm of rows 0.1 mm apart, nearly solid blue.
    const PixelBounds blue = find_hue(back, cncrun::panel_box(View::Top), Hue::Blue);
    const double side_px = 99.9 * scale(View::Top, 99.9, 99.9);
    EXPECT_NEAR(blue.width(), side_px, kLinePx);
    EXPECT_NEAR(blue.height(), side_px, kLinePx);
    EXPECT_GT(blue.count, 0.9 * side_px * side_px);
    SvgScan scan;
    EXPECT_EQ(parse_svg(slurp(svg), scan), "");
    // Generous: a slow, shared CI machine; measured figures are printed above.
    EXPECT_LT(s(t0, t3), 20.0);
}

}  // namespace
