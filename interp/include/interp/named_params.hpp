#pragma once
// Named parameters (#CURMACHPOS.X, #SAFEHEIGHT, …): the table of S0 §4.1.2 (VAR-03) and the V5.4
// internal parameters #SS… of S1 §3.4 (VAR-04). They are read-only and are answered by the
// MachineQuery the caller provides; lengths come back in program units.
#include <optional>
#include <span>
#include <string_view>

#include "interp/block.hpp"
#include "interp/dialect.hpp"

namespace interp {

enum class ParamKind {
    MachinePos,  // index = axis
    WorkPos,     // index = axis
    InputMap,    // all input ports as a bit map
    OutputMap,   // all output ports as a bit map
    InputBit,    // index = port
    OutputBit,   // index = port
    SpindleRpm,
    Setting,  // a machine setting, asked for by name
};

struct NamedParam {
    std::string_view name;  // canonical upper-case name, with axis suffix where it has one
    ParamKind kind;
    int index = 0;
    bool length = false;    // value is a length or a linear speed: converted from mm
    bool writable = false;  // a program may assign it; the value persists (TSET-2)
};

// The 50 entries of S0 §4.1.2, in the manual's order.
std::span<const NamedParam> ncstudio_named_params();

// Resolves the text after '#' (case-insensitive; spaces after the '.' are ignored) in the
// parameter sets the dialect accepts. std::nullopt when it names no parameter.
std::optional<NamedParam> find_named_param(std::string_view text, const Dialect& dialect);

// Reads a parameter through the machine interface. Throws Error at `loc` when a setting is not
// configured on this machine.
double read_named_param(const NamedParam& p, MachineQuery& machine, const SourceLoc& loc);

}  // namespace interp
