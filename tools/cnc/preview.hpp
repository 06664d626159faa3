// `cnc run --preview FILE.svg`: a picture of the path the machine followed, in three views at
// one scale (XY from above, XZ from the front, YZ from the side), rapids and feed moves in
// different colours.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace cncrun {

enum class MoveKind : std::uint8_t { Other, Rapid, Feed };

// For each line of the main program (index = line number), whether it moves at the rapid or
// the feed rate, from the interpreter's canonical stream. A line with both (a canned cycle)
// counts as feed. Throws interp::Error (`file:line:col: reason`) for a bad program.
std::vector<MoveKind> classify_lines(const std::string& program, const std::string& dialect);

class Preview {
  public:
    explicit Preview(std::vector<MoveKind> line_kinds) : line_kinds_(std::move(line_kinds)) {}
    // One sample of the commanded position (mm) and the program line it belongs to.
    void add(const std::array<double, 3>& xyz_mm, int line);
    // Writes the SVG; throws std::runtime_error when the file cannot be written.
    void write_svg(const std::string& path, const std::string& title) const;

  private:
    struct Run {
        MoveKind kind;
        std::vector<std::array<double, 3>> points;
    };
    std::vector<MoveKind> line_kinds_;
    std::vector<Run> runs_;
};

}  // namespace cncrun
