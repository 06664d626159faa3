#pragma once
// The seam between the interpreter's front end (source, lexer, parser, expressions, variables,
// control flow) and its back end (modal state, transforms, canonical output).
//
// The front end turns text into `Block`s whose numbers are already evaluated, resolves control
// flow itself (O labels, M98/M99/M17, G65, public.dat custom codes, IF), and hands every
// remaining executable block to a `BlockExecutor`. Named parameters such as #CURMACHPOS.X read
// machine state through a `MachineQuery`. The back end implements both interfaces.
//
// Units: numbers in a Block are in program units exactly as written (mm or inch, degrees, mm/min,
// ms for G04 P); the back end applies modal state. MachineQuery answers in mm (degrees for rotary
// axes) and the front end converts to program units with mm_per_program_unit().
#include <array>
#include <bit>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "interp/static_vec.hpp"

namespace interp {

// Where something is in a program. `file` points at a name owned by the Interpreter (or by
// whoever built the location) and stays valid while that owner lives; copy it into a
// std::string to keep it longer. Lines and columns count from 1; 0 means "unknown".
struct SourceLoc {
    std::string_view file;
    int line = 0;
    int col = 0;
};

// Every diagnostic of the interpreter. what() is "file:line:col: reason". Thrown only in the
// configuration world (the interpreter thread), never on a realtime path.
class Error : public std::runtime_error {
  public:
    Error(const SourceLoc& loc, const std::string& reason)
        : std::runtime_error(format(loc, reason)),
          file_(loc.file),
          line_(loc.line),
          col_(loc.col),
          reason_(reason) {}

    const std::string& file() const { return file_; }
    int line() const { return line_; }
    int col() const { return col_; }
    const std::string& reason() const { return reason_; }

  private:
    static std::string format(const SourceLoc& loc, const std::string& reason) {
        return std::string(loc.file) + ":" + std::to_string(loc.line) + ":" +
               std::to_string(loc.col) + ": " + reason;
    }
    std::string file_;
    int line_;
    int col_;
    std::string reason_;
};

// G codes are stored as integers scaled by ten so that decimal codes need no floating compare:
// G0 -> 0, G1 -> 10, G50.1 -> 501, G54.1 -> 541, G992 -> 9920.
constexpr int gcode(int whole, int tenth = 0) {
    return whole * 10 + tenth;
}

// Index of an address letter in Block::words: 'A' -> 0 … 'Z' -> 25.
constexpr int letter_index(char c) {
    return (c >= 'a' && c <= 'z') ? c - 'a' : c - 'A';
}

// NcStudio multi-letter keywords of the extended codes (G904, G906, G916, M901; S0 §3.9–3.10).
// Index 0/1/2 of the per-axis arrays is X/Y/Z.
struct NcKeywords {
    std::optional<int> plc;                       // PLC[addr] or PLC=int-expr: PLC port address
    std::optional<int> level;                     // LEVEL n: port level 0/1
    std::array<std::optional<double>, 3> f_axis;  // FX FY FZ: G904 speed and direction per axis
    std::array<std::optional<int>, 3> p_axis;     // PX PY PZ: PLC address ([addr] or =expr)
    std::array<std::optional<int>, 3> l_axis;     // LX LY LZ: level to wait for per axis

    bool empty() const {
        if (plc || level) return false;
        for (int i = 0; i < 3; ++i)
            if (f_axis[i] || p_axis[i] || l_axis[i]) return false;
        return true;
    }
};

// One parsed and evaluated block, ready for the back end. Control-flow words (O, M98, M99, M17,
// G65 and its P/L, IF, `#n=` assignments, public.dat custom codes) have been removed already.
struct Block {
    static constexpr int kMaxCodes = 16;

    SourceLoc loc;                    // the block's first character
    std::optional<std::int64_t> n;    // sequence number N
    StaticVec<int, kMaxCodes> g;      // G codes, scaled x10 (see gcode()), in written order
    StaticVec<int, kMaxCodes> g_col;  // column of each entry of g
    StaticVec<int, kMaxCodes> m;      // M codes in written order
    StaticVec<int, kMaxCodes> m_col;  // column of each entry of m
    std::array<std::optional<double>, 26> words;  // address letters A..Z except G, M, N, O
    std::array<int, 26> word_col{};  // column of each present word; read it through col()
    // Bit i set: letter 'A'+i was written as a plain integer literal without a decimal point
    // (ISO standard-notation scaling needs to know; LEX-52).
    std::uint32_t integer_literal_mask = 0;
    std::optional<std::string> msg;  // M801 MSG "text" (V5.4: M801 "text")
    NcKeywords kw;                   // PLC, LEVEL, FX.., PX.., LX..

    // Back to an empty block, cheaper than assigning Block{} (only the used parts are reset).
    // `word_mask` limits which letters are reset (bit i = 'A'+i) when the caller knows which
    // ones can be set.
    void clear(std::uint32_t word_mask = (1u << 26) - 1) {
        loc = SourceLoc{};
        n.reset();
        g.clear();
        g_col.clear();
        m.clear();
        m_col.clear();
        for (std::uint32_t bits = word_mask; bits != 0; bits &= bits - 1)
            words[std::countr_zero(bits)].reset();
        integer_literal_mask = 0;
        msg.reset();
        kw = NcKeywords{};
    }

    bool has(char letter) const { return words[letter_index(letter)].has_value(); }
    // The value of a present word; call has() first (throws std::bad_optional_access otherwise).
    double get(char letter) const { return words[letter_index(letter)].value(); }
    std::optional<double> opt(char letter) const { return words[letter_index(letter)]; }
    int col(char letter) const {
        const int i = letter_index(letter);
        return words[i] ? word_col[i] : 0;
    }
    SourceLoc loc_of(char letter) const {
        int c = col(letter);
        return SourceLoc{loc.file, loc.line, c != 0 ? c : loc.col};
    }
    bool has_g(int scaled) const { return g.contains(scaled); }
    bool has_m(int code) const { return m.contains(code); }
    // True when nothing executable is left (an empty line, a comment, or only assignments).
    bool empty() const {
        if (!g.empty() || !m.empty() || msg || !kw.empty()) return false;
        for (const auto& w : words)
            if (w) return false;
        return true;
    }
};

// Receives warnings: input that is accepted but is probably not what the program means
// (a duplicate sequence number, …). A warning never stops the program. Called on the
// interpreter's thread. The back end's warnings travel in the canonical stream instead
// (canon::Warning), in program order with the commands they concern.
class WarningSink {
  public:
    virtual ~WarningSink() = default;
    virtual void warning(const SourceLoc& loc, const std::string& text) = 0;
};

// The back end. The front end calls execute() once per executable block, in program order, after
// control flow is resolved. execute() throws interp::Error to reject a block; a rejected block
// must leave the back end's state unchanged (the front end then rolls back the block's
// variable assignments too). M02/M30 blocks are passed on like any other block; the front end
// stops reading after them.
class BlockExecutor {
  public:
    virtual ~BlockExecutor() = default;
    virtual void execute(const Block& block) = 0;
    // The program ended by running off the end of the main file without M02/M30. `loc` is the
    // position just past the last line. The back end decides what a normal end means (END-1).
    virtual void end_of_input(const SourceLoc& loc) = 0;
};

// Axis indices used by MachineQuery.
enum class Axis : int { X = 0, Y = 1, Z = 2, A = 3, B = 4, C = 5 };
constexpr int kMachineAxes = 6;

// What named parameters (#CURMACHPOS.X, #IMPORTMAP, #SAFEHEIGHT, …) read. Standalone, the back
// end answers from its own model; on a machine, the live values wait until motion has caught up
// (NcStudio's G906 semantics), so the front end may call them at any time.
class MachineQuery {
  public:
    virtual ~MachineQuery() = default;
    // Live state. Linear axes in mm, rotary axes in degrees.
    virtual double machine_pos_mm(Axis axis) = 0;
    virtual double work_pos_mm(Axis axis) = 0;
    virtual std::uint64_t input_bits() = 0;   // bit n = input port n
    virtual std::uint64_t output_bits() = 0;  // bit n = output port n
    virtual double spindle_rpm() = 0;
    // Modal state the front end needs: 1.0 under G21/G71, 25.4 under G20/G70.
    virtual double mm_per_program_unit() = 0;
    // G91 active (fills #FC13 when a public.dat custom G code replaces a canned cycle).
    virtual bool incremental_mode() = 0;
    // G99 (return to the R plane) active rather than G98 (fills #FC12).
    virtual bool cycle_return_to_r() = 0;
    // A configured or persisted machine setting of the manual's named-parameter table, by its
    // canonical upper-case name with axis suffix ("SAFEHEIGHT", "BKREF_F1.X", "FIXEDCALI_REC").
    // Lengths in mm. std::nullopt when the machine has no such setting configured.
    virtual std::optional<double> setting(std::string_view name) = 0;
    // Whether this machine keeps the writable named parameter `name` (#FIXEDCALI_REC, TSET-2).
    // Asked while the block is parsed, so a refused write rejects the block before anything runs.
    virtual bool can_write_setting(std::string_view /*name*/) { return false; }
    // Stores it (lengths in mm) so that it persists. Called after the block that wrote it was
    // executed, never for a rejected block, and only when can_write_setting() said yes.
    virtual void write_setting(std::string_view name, double /*value*/) {
        throw std::logic_error("write_setting(" + std::string(name) +
                               ") on a machine that keeps no settings");
    }
};

}  // namespace interp
