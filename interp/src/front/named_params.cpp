#include "interp/named_params.hpp"

#include <array>
#include <string>

#include "interp/text.hpp"

namespace interp {

namespace {

using K = ParamKind;
constexpr int X = 0, Y = 1, Z = 2;

// S0 §4.1.2, entries 01–50. `length` marks values the manual gives in mm or mm/min. Only
// FIXEDCALI_REC is written by programs: the fixed tool-setting routine records the contact Z in it
// (TSET-2); every other entry is a machine setting, read-only to programs (VAR-03).
constexpr std::array<NamedParam, 50> kNcStudioParams{{
    {"CURMACHPOS.X", K::MachinePos, X, true},     {"CURMACHPOS.Y", K::MachinePos, Y, true},
    {"CURMACHPOS.Z", K::MachinePos, Z, true},     {"CURWORKPOS.X", K::WorkPos, X, true},
    {"CURWORKPOS.Y", K::WorkPos, Y, true},        {"CURWORKPOS.Z", K::WorkPos, Z, true},
    {"IMPORTMAP", K::InputMap, 0, false},         {"OUTPORTMAP", K::OutputMap, 0, false},
    {"SAFEHEIGHT", K::Setting, 0, true},          {"ISYREVAXIS", K::Setting, 0, false},
    {"WPREVDIAM", K::Setting, 0, true},           {"UNIT.YR", K::Setting, 0, false},
    {"AUTOSTOPSPINDLE", K::Setting, 0, false},    {"SPINDLE_DELAY", K::Setting, 0, false},
    {"MOBICALI_THICKNESS", K::Setting, 0, true},  {"FIXEDCALI_POS.X", K::Setting, 0, true},
    {"FIXEDCALI_POS.Y", K::Setting, 0, true},     {"FIXEDCALI_POS.Z", K::Setting, 0, true},
    {"ENABLE_CTP", K::Setting, 0, false},         {"CTP_POS.X", K::Setting, 0, true},
    {"CTP_POS.Y", K::Setting, 0, true},           {"CTP_POS.Z", K::Setting, 0, true},
    {"BKREF_SW1.X", K::Setting, 0, false},        {"BKREF_SW1.Y", K::Setting, 0, false},
    {"BKREF_SW1.Z", K::Setting, 0, false},        {"BKREF_SW2.X", K::Setting, 0, false},
    {"BKREF_SW2.Y", K::Setting, 0, false},        {"BKREF_SW2.Z", K::Setting, 0, false},
    {"BKREF_F1.X", K::Setting, 0, true},          {"BKREF_F1.Y", K::Setting, 0, true},
    {"BKREF_F1.Z", K::Setting, 0, true},          {"BKREF_F1_DIR.X", K::Setting, 0, false},
    {"BKREF_F1_DIR.Y", K::Setting, 0, false},     {"BKREF_F1_DIR.Z", K::Setting, 0, false},
    {"BKREF_F2.X", K::Setting, 0, true},          {"BKREF_F2.Y", K::Setting, 0, true},
    {"BKREF_F2.Z", K::Setting, 0, true},          {"BKREF_F2_DIR.X", K::Setting, 0, false},
    {"BKREF_F2_DIR.Y", K::Setting, 0, false},     {"BKREF_F2_DIR.Z", K::Setting, 0, false},
    {"BKREF_BACK.X", K::Setting, 0, true},        {"BKREF_BACK.Y", K::Setting, 0, true},
    {"BKREF_BACK.Z", K::Setting, 0, true},        {"CALIBRATION_SW", K::Setting, 0, false},
    {"SPINDLE_START_PORT", K::Setting, 0, false}, {"COOLANT_START_PORT", K::Setting, 0, false},
    {"DD_BKREF_DELTA", K::Setting, 0, true},      {"FIXEDCYCLE_BACK", K::Setting, 0, true},
    {"FIXEDCYCLE_OSS", K::Setting, 0, false},     {"FIXEDCALI_REC", K::Setting, 0, true, true},
}};

// "CTP_POS. x" -> "CTP_POS.X"
std::string normalize(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text)
        if (!is_space(c)) out.push_back(to_upper(c));
    return out;
}

// "SSINPORT12" with prefix "SSINPORT" -> 12; nullopt if the rest is not a number in [0, max].
std::optional<int> indexed(std::string_view name, std::string_view prefix, int max) {
    if (name.size() <= prefix.size() || name.substr(0, prefix.size()) != prefix)
        return std::nullopt;
    int n = 0;
    for (char c : name.substr(prefix.size())) {
        if (!is_digit(c) || n > max) return std::nullopt;
        n = n * 10 + (c - '0');
    }
    if (n > max) return std::nullopt;
    return n;
}

// S1 §3.4: #SSCURPOS0..2, #SSCURWORKCOOR0..2, #SSINPORT0..63, #SSOUTPORT0..63, #SSSPINDLEREV.
std::optional<NamedParam> find_v54(std::string_view name) {
    if (name == "SSSPINDLEREV") return NamedParam{"SSSPINDLEREV", K::SpindleRpm, 0, false};
    if (auto n = indexed(name, "SSCURPOS", 2))
        return NamedParam{"SSCURPOS", K::MachinePos, *n, true};
    if (auto n = indexed(name, "SSCURWORKCOOR", 2))
        return NamedParam{"SSCURWORKCOOR", K::WorkPos, *n, true};
    if (auto n = indexed(name, "SSINPORT", 63))
        return NamedParam{"SSINPORT", K::InputBit, *n, false};
    if (auto n = indexed(name, "SSOUTPORT", 63))
        return NamedParam{"SSOUTPORT", K::OutputBit, *n, false};
    return std::nullopt;
}

}  // namespace

std::span<const NamedParam> ncstudio_named_params() {
    return kNcStudioParams;
}

std::optional<NamedParam> find_named_param(std::string_view text, const Dialect& dialect) {
    const std::string name = normalize(text);
    if (dialect.v6_named_params) {
        for (const NamedParam& p : kNcStudioParams)
            if (p.name == name) return p;
    }
    if (dialect.v54_named_params) return find_v54(name);
    return std::nullopt;
}

double read_named_param(const NamedParam& p, MachineQuery& machine, const SourceLoc& loc) {
    const double to_program = p.length ? 1.0 / machine.mm_per_program_unit() : 1.0;
    switch (p.kind) {
        case K::MachinePos:
            return machine.machine_pos_mm(static_cast<Axis>(p.index)) * to_program;
        case K::WorkPos:
            return machine.work_pos_mm(static_cast<Axis>(p.index)) * to_program;
        case K::InputMap:
            return static_cast<double>(machine.input_bits());
        case K::OutputMap:
            return static_cast<double>(machine.output_bits());
        case K::InputBit:
            return static_cast<double>((machine.input_bits() >> p.index) & 1u);
        case K::OutputBit:
            return static_cast<double>((machine.output_bits() >> p.index) & 1u);
        case K::SpindleRpm:
            return machine.spindle_rpm();
        case K::Setting: {
            const std::optional<double> v = machine.setting(p.name);
            if (!v) {
                throw Error(loc, "named parameter #" + std::string(p.name) +
                                     " is not configured on this machine");
            }
            return *v * to_program;
        }
    }
    throw Error(loc, "named parameter #" + std::string(p.name) + " cannot be read");
}

}  // namespace interp
