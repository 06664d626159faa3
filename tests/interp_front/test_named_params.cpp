#include <gtest/gtest.h>

#include <cctype>
#include <stdexcept>
#include <string>
#include <vector>

#include "fakes.hpp"
#include "interp/expr.hpp"
#include "interp/named_params.hpp"
#include "interp/text.hpp"

using namespace interp;

namespace {

double read(std::string_view text, test::FakeMachine& m, const Dialect& d = ncstudio_dialect()) {
    const auto p = find_named_param(text, d);
    if (!p) throw std::runtime_error("unknown " + std::string(text));
    return read_named_param(*p, m, SourceLoc{"n.nc", 1, 1});
}

}  // namespace

// S0 §4.1.2 lists 50 parameters; spot-check the manual's numbering at both ends and the middle.
TEST(NamedParams, TableHasTheManualsFiftyEntriesInOrder) {
    const auto t = ncstudio_named_params();
    ASSERT_EQ(t.size(), 50u);
    EXPECT_EQ(t[0].name, "CURMACHPOS.X");      // 01
    EXPECT_EQ(t[6].name, "IMPORTMAP");         // 07
    EXPECT_EQ(t[11].name, "UNIT.YR");          // 12
    EXPECT_EQ(t[22].name, "BKREF_SW1.X");      // 23
    EXPECT_EQ(t[43].name, "CALIBRATION_SW");   // 44
    EXPECT_EQ(t[47].name, "FIXEDCYCLE_BACK");  // 48
    EXPECT_EQ(t[49].name, "FIXEDCALI_REC");    // 50
}

// Every entry resolves case-insensitively and reads its own value through MachineQuery.
TEST(NamedParams, EveryEntryReadsThroughMachineQuery) {
    test::FakeMachine m;
    m.machine_mm = {1.5, 2.5, 3.5, 0, 0, 0};
    m.work_mm = {-1.5, -2.5, -3.5, 0, 0, 0};
    m.inputs = 0b1011;
    m.outputs = 0b0100;
    double v = 100.0;
    for (const NamedParam& p : ncstudio_named_params()) {
        if (p.kind == ParamKind::Setting) m.settings[std::string(p.name)] = (v += 1.0);
    }
    v = 100.0;
    for (const NamedParam& p : ncstudio_named_params()) {
        std::string lower(p.name);
        for (char& c : lower) c = static_cast<char>(std::tolower(c));
        double expected = 0;
        switch (p.kind) {
            case ParamKind::MachinePos:
                expected = m.machine_mm[p.index];
                break;
            case ParamKind::WorkPos:
                expected = m.work_mm[p.index];
                break;
            case ParamKind::InputMap:
                expected = 11;
                break;
            case ParamKind::OutputMap:
                expected = 4;
                break;
            case ParamKind::Setting:
                expected = (v += 1.0);
                break;
            default:
                FAIL() << p.name;
        }
        EXPECT_EQ(read(lower, m), expected) << p.name;
    }
    EXPECT_EQ(read("CURMACHPOS.X", m), 1.5);
    EXPECT_EQ(read("CURWORKPOS.Z", m), -3.5);
    EXPECT_EQ(read("CTP_POS. Z", m), m.settings["CTP_POS.Z"]);  // S0 prints a space after '.'
}

// Positions and lengths are returned in program units; ports and flags are not scaled.
TEST(NamedParams, LengthsConvertToInchPrograms) {
    test::FakeMachine m;
    m.mm_per_unit = 25.4;
    m.machine_mm[2] = 50.8;
    m.settings["SAFEHEIGHT"] = 25.4;
    m.settings["COOLANT_START_PORT"] = 24;
    m.settings["BKREF_F1.X"] = 254.0;  // mm/min -> 10 inch/min
    EXPECT_DOUBLE_EQ(read("CURMACHPOS.Z", m), 2.0);
    EXPECT_DOUBLE_EQ(read("SAFEHEIGHT", m), 1.0);
    EXPECT_DOUBLE_EQ(read("COOLANT_START_PORT", m), 24.0);
    EXPECT_DOUBLE_EQ(read("BKREF_F1.X", m), 10.0);
}

// S1 §3.4 internal parameters exist only with the V5.4 switch.
TEST(NamedParams, V54NamesBehindCompatSwitch) {
    test::FakeMachine m;
    m.machine_mm = {1, 2, 3, 0, 0, 0};
    m.work_mm = {4, 5, 6, 0, 0, 0};
    m.inputs = 1ull << 63 | 1ull << 5;
    m.outputs = 1ull << 2;
    m.rpm = 12000;
    EXPECT_FALSE(find_named_param("SSCURPOS0", ncstudio_dialect()));
    const Dialect& d = ncstudio_v54_dialect();
    EXPECT_EQ(read("SSCURPOS1", m, d), 2.0);
    EXPECT_EQ(read("sscurworkcoor2", m, d), 6.0);
    EXPECT_EQ(read("SSINPORT5", m, d), 1.0);
    EXPECT_EQ(read("SSINPORT4", m, d), 0.0);
    EXPECT_EQ(read("SSINPORT63", m, d), 1.0);
    EXPECT_EQ(read("SSOUTPORT2", m, d), 1.0);
    EXPECT_EQ(read("SSSPINDLEREV", m, d), 12000.0);
    EXPECT_FALSE(find_named_param("SSINPORT64", d));
    EXPECT_FALSE(find_named_param("SSCURPOS3", d));
    // The 6th-edition names remain available in V5.4 mode.
    EXPECT_EQ(read("CURMACHPOS.X", m, d), 1.0);
}
