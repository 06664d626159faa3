// G992's implicit sync (FEATURES G992-3 REC) and MIR-5's ISO rule that coordinate changes are
// refused while mirroring. Expected texts worked out by hand from the rules named.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "block_builder.hpp"
#include "interp/executor.hpp"

namespace interp {
namespace {

struct Lines : CanonSink {
    std::vector<std::string> text;
    void emit(const Canon& c) override { text.push_back(to_text(c)); }
};

using V = std::vector<std::string>;

V run(const std::vector<std::string>& lines, BackendConfig cfg = {}) {
    Lines out;
    Executor e(out, cfg);
    int n = 0;
    for (const auto& l : lines) e.execute(test::blk(l, ++n));
    V v;
    for (const auto& t : out.text)
        if (t.find(" offsets ") == std::string::npos) v.push_back(t);
    return v;
}

TEST(G992Sync, G992AfterAMoveSyncsFirst) {
    // Line 2's G992 reads the current point (X10), so the machine must have arrived: sync.
    EXPECT_EQ(run({"G00 X10", "G992 X0"}), (V{"1 traverse X10 Y0 Z0", "2 sync"}));
}

TEST(G992Sync, NoSecondSyncAfterG906OrWithoutMotion) {
    EXPECT_EQ(run({"G00 X10", "G906", "G992 X0", "G992 I5"}),
              (V{"1 traverse X10 Y0 Z0", "2 sync"}));
    EXPECT_EQ(run({"G992 X3"}), V{});  // nothing has moved since the start
}

TEST(G992Sync, IjkFormSyncsTooAndEachMoveArmsItAgain) {
    // G992 I5 shifts the temporary origin to machine X5, so work X1 is machine X6.
    EXPECT_EQ(run({"G00 X10", "G992 I5", "G01 X1 F60", "G992 I5"}),
              (V{"1 traverse X10 Y0 Z0", "2 sync", "3 feed-rate 1mm/s", "3 feed X6 Y0 Z0",
                 "4 sync"}));
}

std::string error_of(const std::vector<std::string>& lines, BackendConfig cfg) {
    try {
        run(lines, cfg);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(Mir5, CoordinateChangesRefusedWhileMirroringWhenConfigured) {
    BackendConfig iso;
    iso.mirror_forbids_coord_changes = true;
    for (const char* code : {"G92 X0", "G55", "G28 X0", "G53 X0", "G921 X0", "G922 X0", "G992 X0"}) {
        const std::string c = std::string(code).substr(0, std::string(code).find(' '));
        EXPECT_EQ(error_of({"G51.1 X0", code}, iso),
                  "test.nc:2:1: " + c + " is not allowed while mirroring (G51.1) is active")
            << code;
    }
    // After G50.1 the codes are allowed again.
    EXPECT_EQ(error_of({"G51.1 X0", "G50.1", "G92 X0", "G55"}, iso), "no error");
}

TEST(Mir5, NcStudioAllowsThem) {
    EXPECT_EQ(error_of({"G51.1 X0", "G92 X0", "G55"}, BackendConfig{}), "no error");
}

// C-37: units belong at the start; after a move they still apply, with a warning.
TEST(UnitsWarning, G20AfterAMoveWarns) {
    EXPECT_EQ(run({"G21 G00 X1", "G20"}),
              (V{"1 units mm", "1 traverse X1 Y0 Z0",
                 "2 warning \"G20/G21 after a move: units belong at the start of the program\"",
                 "2 units inch"}));
    EXPECT_EQ(run({"G20", "G00 X1"}), (V{"1 units inch", "2 traverse X25.4 Y0 Z0"}));
}

}  // namespace
}  // namespace interp
