// A hand-written LinuxCNC tool table survives a save: update_linuxcnc_tool_table keeps every
// byte but the values that changed. Every expected text here is the input with the one change
// named in the test written in by hand.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "interp/block.hpp"
#include "interp/persist.hpp"
#include "interp/tooltable.hpp"
#include "scratch_dir.hpp"

namespace interp {
namespace {

namespace fs = std::filesystem;

// Every word LinuxCNC's .tbl has, comment-only, blank and indented lines, a comment without a
// space before it, lower case, a '+' sign, an exponent, and the tools not in number order.
const std::string kHand =
    "; Tool table of the Smith mill, kept by hand\n"
    ";T  P  X  Y  Z      A  B  C  U  V  W  D      I  J  Q\n"
    "T1 P1 X0 Y0 Z40.000 A0 B0 C0 U0 V0 W0 D6.000 I0 J0 Q0 ;6 mm flat end mill\n"
    "T12 P5 Z35 D3 I10 J20 Q1;drill: lathe words kept\n"
    "\n"
    "t7 p7 z+50.5 d10 a1.5  ; lower case, spaces kept\n"
    "T4 P4 D10 Z50 U-0.25 W1e-3 ;10 mm drill\n"
    "   ; an indented comment after the tools\n";

std::string rewrite(const std::string& text, const ToolTable& t) {
    return update_linuxcnc_tool_table(text, t, "t.tbl");
}

std::string error_of_rewrite(const std::string& text) {
    try {
        rewrite(text, ToolTable{});
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(ToolTableRewrite, UnchangedTableIsKeptByteForByte) {
    const ToolTable t = parse_linuxcnc_tool_table(kHand, "t.tbl");
    EXPECT_EQ(rewrite(kHand, t), kHand);
    // The reader's view of the hand-written lines, so the cases below start from known values.
    ASSERT_NE(t.find(12), nullptr);
    EXPECT_EQ(t.find(12)->offset_mm[2], 35);
    EXPECT_EQ(t.find(12)->pocket, 5);
    EXPECT_EQ(t.find(1)->offset_mm[2], 40);
    EXPECT_EQ(t.find(7)->offset_mm[2], 50.5);
    EXPECT_EQ(t.find(4)->comment, "10 mm drill");
}

TEST(ToolTableRewrite, OneChangedLengthChangesOnlyItsNumber) {
    ToolTable t = parse_linuxcnc_tool_table(kHand, "t.tbl");
    t.at(12).offset_mm[2] = 36.25;
    EXPECT_EQ(rewrite(kHand, t),
              "; Tool table of the Smith mill, kept by hand\n"
              ";T  P  X  Y  Z      A  B  C  U  V  W  D      I  J  Q\n"
              "T1 P1 X0 Y0 Z40.000 A0 B0 C0 U0 V0 W0 D6.000 I0 J0 Q0 ;6 mm flat end mill\n"
              "T12 P5 Z36.25 D3 I10 J20 Q1;drill: lathe words kept\n"
              "\n"
              "t7 p7 z+50.5 d10 a1.5  ; lower case, spaces kept\n"
              "T4 P4 D10 Z50 U-0.25 W1e-3 ;10 mm drill\n"
              "   ; an indented comment after the tools\n");
}

TEST(ToolTableRewrite, ChangedNumbersKeepTheLetterAsWritten) {
    ToolTable t = parse_linuxcnc_tool_table(kHand, "t.tbl");
    t.at(7).offset_mm[2] = 50;
    t.at(7).diameter_mm = 9.5;
    t.at(1).offset_mm[1] = -2;
    const std::string out = rewrite(kHand, t);
    EXPECT_NE(out.find("\nt7 p7 z50 d9.5 a1.5  ; lower case, spaces kept\n"), std::string::npos)
        << out;
    EXPECT_NE(out.find("\nT1 P1 X0 Y-2 Z40.000 A0 B0 C0 U0 V0 W0 D6.000 I0 J0 Q0 ;6 mm flat "
                       "end mill\n"),
              std::string::npos)
        << out;
}

// A word the line lacks goes after its last word, before the blanks and the comment.
TEST(ToolTableRewrite, AMissingWordIsAddedAfterTheLastWord) {
    ToolTable t = parse_linuxcnc_tool_table(kHand, "t.tbl");
    t.at(7).offset_mm[0] = 1.5;
    t.at(12).offset_mm[1] = 0.125;
    const std::string out = rewrite(kHand, t);
    EXPECT_NE(out.find("\nt7 p7 z+50.5 d10 a1.5 X1.5  ; lower case, spaces kept\n"),
              std::string::npos)
        << out;
    EXPECT_NE(out.find("\nT12 P5 Z35 D3 I10 J20 Q1 Y0.125;drill: lathe words kept\n"),
              std::string::npos)
        << out;
}

TEST(ToolTableRewrite, NewToolsAreAppendedInToolOrder) {
    ToolTable t = parse_linuxcnc_tool_table(kHand, "t.tbl");
    t.at(9).offset_mm = {0, 0, 20};
    t.at(2).offset_mm = {1, 0, 22.5};
    t.at(2).diameter_mm = 4;
    EXPECT_EQ(rewrite(kHand, t), kHand + "T2 P2 X1 Z22.5 D4\nT9 P9 Z20 D0\n");
}

TEST(ToolTableRewrite, LineEndingsAndAMissingLastNewlineAreKept) {
    const std::string crlf = "T1 P1 Z40 ;a\r\nT2 P2 Z35";
    ToolTable t = parse_linuxcnc_tool_table(crlf, "t.tbl");
    EXPECT_EQ(rewrite(crlf, t), crlf);
    t.at(2).offset_mm[2] = 30;
    EXPECT_EQ(rewrite(crlf, t), "T1 P1 Z40 ;a\r\nT2 P2 Z30");
    t.at(3).offset_mm[2] = 5;
    EXPECT_EQ(rewrite(crlf, t), "T1 P1 Z40 ;a\r\nT2 P2 Z30\r\nT3 P3 Z5 D0\r\n");
}

// The reader takes the last of a repeated word, so that is the one the writer changes.
TEST(ToolTableRewrite, ARepeatedWordChangesWhereTheReaderTookIt) {
    const std::string text = "T1 Z10 Z20 D1\n";
    ToolTable t = parse_linuxcnc_tool_table(text, "t.tbl");
    EXPECT_EQ(t.find(1)->offset_mm[2], 20);
    t.at(1).offset_mm[2] = 25;
    EXPECT_EQ(rewrite(text, t), "T1 Z10 Z25 D1\n");
}

TEST(ToolTableRewrite, CommentsAreReplacedOrAdded) {
    const std::string text = "T2 P2 Z35;  old\nT3 P3 Z1\n";
    ToolTable t = parse_linuxcnc_tool_table(text, "t.tbl");
    t.at(2).comment = "new";
    t.at(3).comment = "added";
    EXPECT_EQ(rewrite(text, t), "T2 P2 Z35;  new\nT3 P3 Z1 ;added\n");
}

// Nothing removes a tool from the table, but a line for a tool the table lacks is not dropped.
TEST(ToolTableRewrite, ALineForAToolNotInTheTableStays) {
    EXPECT_EQ(rewrite("T1 P1 Z40 ;x\n", ToolTable{}), "T1 P1 Z40 ;x\n");
}

TEST(ToolTableRewrite, ANewTableIsWrittenInTheReadersForm) {
    ToolTable t;
    t.at(3).offset_mm = {0, 0, 45};
    t.at(3).diameter_mm = 6;
    t.at(3).comment = "ball";
    t.at(1).pocket = 7;
    EXPECT_EQ(format_linuxcnc_tool_table(t), "T1 P7 Z0 D0\nT3 P3 Z45 D6 ;ball\n");
    EXPECT_EQ(rewrite("", t), format_linuxcnc_tool_table(t));
}

TEST(ToolTableRewrite, ABadTableIsRefusedWithItsLine) {
    EXPECT_EQ(error_of_rewrite("T1 P1\nT2 Zq\n"),
              "t.tbl:2:5: tool table: expected a number after 'Z'");
    EXPECT_EQ(error_of_rewrite("T1 P1\nT1 P2\n"), "t.tbl:2:1: tool table: tool 1 listed twice");
    EXPECT_EQ(error_of_rewrite("T1 Zinf\n"), "t.tbl:1:5: tool table: value is not a finite number");
    EXPECT_EQ(error_of_rewrite("T1 Znan\n"), "t.tbl:1:5: tool table: value is not a finite number");
}

// The file on disk is the base of a save: its seed while it does not exist yet.
TEST(ToolTableRewrite, SaveEditsTheFileOrItsSeed) {
    const cnc_test::ScratchDir scratch;
    const std::string seed = (scratch.path() / "seed.tbl").string();
    const std::string file = (scratch.path() / "t.tbl").string();
    std::ofstream(seed) << kHand;
    ToolTable t = parse_linuxcnc_tool_table(kHand, "t.tbl");
    t.at(4).diameter_mm = 12;
    save_tool_table_atomic(file, t, seed);
    std::string expected = kHand;
    expected.replace(expected.find("T4 P4 D10"), 9, "T4 P4 D12");
    EXPECT_EQ(cnc_test::slurp(file), expected);
    EXPECT_EQ(cnc_test::slurp(seed), kHand);
    // The second save starts from the file, not the seed.
    t.at(4).offset_mm[2] = 51;
    save_tool_table_atomic(file, t, seed);
    expected.replace(expected.find("D12 Z50"), 7, "D12 Z51");
    EXPECT_EQ(cnc_test::slurp(file), expected);
    EXPECT_FALSE(fs::exists(file + ".tmp"));
}

// A table that was edited into something the reader refuses is not overwritten.
TEST(ToolTableRewrite, SaveOverABadFileFailsAndKeepsIt) {
    const cnc_test::ScratchDir scratch;
    const std::string file = (scratch.path() / "t.tbl").string();
    const std::string bad = "T1 P1 Z40\nT2 R3\n";
    std::ofstream(file) << bad;
    ToolTable t;
    t.at(1).offset_mm[2] = 30;
    try {
        save_tool_table_atomic(file, t);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), file + ":2:4: tool table: unknown word 'R'");
    }
    EXPECT_EQ(cnc_test::slurp(file), bad);
}

}  // namespace
}  // namespace interp
