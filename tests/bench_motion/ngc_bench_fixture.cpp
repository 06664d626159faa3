#include "ngc_bench_fixture.hpp"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>

#include "motion/geometry.hpp"

namespace motion::bench {
namespace {

struct Word {
    char letter;
    double value;
    int col;
};

[[noreturn]] void fail(const std::string& file, int line, int col, const std::string& why) {
    throw std::runtime_error(fmt::format("{}:{}:{}: {}", file, line, col, why));
}

std::vector<Word> split_words(const std::string& text, const std::string& file, int line) {
    std::vector<Word> words;
    std::size_t i = 0;
    while (i < text.size()) {
        char c = text[i];
        if (std::isspace(static_cast<unsigned char>(c))) {
            ++i;
        } else if (c == ';' || c == '%') {
            break;
        } else if (c == '(') {
            std::size_t close = text.find(')', i);
            if (close == std::string::npos) fail(file, line, int(i) + 1, "unclosed comment");
            i = close + 1;
        } else if (std::isalpha(static_cast<unsigned char>(c))) {
            std::size_t start = i++;
            std::size_t used = 0;
            double v = 0;
            try {
                v = std::stod(text.substr(i), &used);
            } catch (const std::exception&) {
                fail(file, line, int(i) + 1, fmt::format("expected a number after '{}'", c));
            }
            words.push_back({char(std::toupper(c)), v, int(start) + 1});
            i += used;
        } else {
            fail(file, line, int(i) + 1, fmt::format("unexpected character '{}'", c));
        }
    }
    return words;
}

}  // namespace

FixtureProgram read_ngc_fixture(const std::string& path, double tolerance_mm) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot open");
    FixtureProgram prog;
    AxisArray pos{};
    int motion = -1;
    double feed_mm_s = 0;
    std::string text;
    for (int line = 1; std::getline(in, text); ++line) {
        std::vector<Word> words = split_words(text, path, line);
        std::map<char, Word> coords;
        bool has_axis = false;
        for (const Word& w : words) {
            switch (w.letter) {
                case 'G': {
                    int g = int(std::lround(w.value));
                    if (g >= 0 && g <= 3)
                        motion = g;
                    else if (g != 17 && g != 21 && g != 90)
                        fail(path, line, w.col, fmt::format("G{} is outside the bench subset", g));
                    break;
                }
                case 'M':
                    if (std::lround(w.value) != 2) fail(path, line, w.col, "only M2 is supported");
                    break;
                case 'F':
                    feed_mm_s = w.value / 60.0;
                    break;
                case 'N':
                    break;
                case 'X':
                case 'Y':
                case 'Z':
                    has_axis = true;
                    [[fallthrough]];
                case 'I':
                case 'J':
                    coords[w.letter] = w;
                    break;
                default:
                    fail(path, line, w.col,
                         fmt::format("word '{}' is outside the bench subset", w.letter));
            }
        }
        if (!has_axis) continue;
        if (motion < 0) fail(path, line, 1, "axis words without a motion mode");
        PathSegment seg;
        seg.end_mm = pos;
        if (coords.count('X')) seg.end_mm[0] = coords['X'].value;
        if (coords.count('Y')) seg.end_mm[1] = coords['Y'].value;
        if (coords.count('Z')) seg.end_mm[2] = coords['Z'].value;
        seg.rapid = motion == 0;
        if (!seg.rapid && feed_mm_s <= 0) fail(path, line, 1, "feed move without F");
        seg.feed_mm_s = feed_mm_s;
        seg.tolerance_mm = tolerance_mm;
        seg.line = line;
        if (motion >= 2) {
            if (!coords.count('I') && !coords.count('J'))
                fail(path, line, 1, "arc needs I or J (R form is outside the bench subset)");
            seg.kind = SegmentKind::Arc;
            seg.centre_mm = {pos[0] + (coords.count('I') ? coords['I'].value : 0),
                             pos[1] + (coords.count('J') ? coords['J'].value : 0)};
            seg.turns = motion == 3 ? 1 : -1;
        }
        prog.segments.push_back(seg);
        pos = seg.end_mm;
    }
    return prog;
}

double programmed_length_mm(const PathSegment& seg, const AxisArray& start) {
    Element e = seg.kind == SegmentKind::Arc ? make_arc(start, seg) : make_line(start, seg.end_mm);
    return e.length_mm;
}

}  // namespace motion::bench
