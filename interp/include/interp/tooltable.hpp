#pragma once
// Tool table: per tool an offset vector (NcStudio G923 writes X Y Z; LinuxCNC's Z is the
// length) and a diameter. Lengths in mm.
#include <array>
#include <map>
#include <string>

namespace interp {

struct ToolEntry {
    std::array<double, 3> offset_mm{};  // X Y Z; Z is the tool length
    double diameter_mm = 0;
    int pocket = 0;
    std::string comment;
    bool operator==(const ToolEntry&) const = default;
};

class ToolTable {
  public:
    // nullptr when the tool is not in the table.
    const ToolEntry* find(int tool) const {
        auto it = tools_.find(tool);
        return it == tools_.end() ? nullptr : &it->second;
    }
    // Creates the entry when missing.
    ToolEntry& at(int tool) { return tools_[tool]; }
    const std::map<int, ToolEntry>& entries() const { return tools_; }
    bool operator==(const ToolTable&) const = default;

  private:
    std::map<int, ToolEntry> tools_;
};

// Reads a LinuxCNC tool table ("T1 P1 D6.0 Z12.5 ;comment", D = diameter, values in machine
// units = mm). Throws interp::Error "file:line:col: cause" on the first bad line.
ToolTable load_linuxcnc_tool_table(const std::string& path);
// The same from text already in memory; `name` is used in error messages.
ToolTable parse_linuxcnc_tool_table(const std::string& text, const std::string& name);

// A new table in the .tbl form, one line per tool in tool order: "T1 P1 Z40 D6 ;comment" (X and
// Y only when not 0; a tool without a pocket gets P = its number).
std::string format_linuxcnc_tool_table(const ToolTable& t);

// `old_text` (a table parse_linuxcnc_tool_table accepts, `name` in its errors) rewritten to hold
// `t`, so that a machine builder's hand-written table survives a save. Every byte of it stays as
// it was (the words the reader ignores, comments, blank and comment-only lines, line order, line
// endings) except: the number of a P D X Y Z word whose value differs from the tool's in `t`
// (written in shortest round-trip form), such a word added before the comment when the line has
// none and the new value is not 0, and the comment when the tool's differs. A line whose tool is
// not in `t` stays as it is; tools of `t` without a line are appended in tool order in
// format_linuxcnc_tool_table's form. Throws interp::Error "name:line:col: cause" for a bad line.
std::string update_linuxcnc_tool_table(const std::string& old_text, const ToolTable& t,
                                       const std::string& name);

}  // namespace interp
