#include <gtest/gtest.h>

#include <string>

#include "fakes.hpp"
#include "interp/parser.hpp"

using namespace interp;

namespace {

struct ParserFixture : ::testing::Test {
    Variables vars;
    test::FakeMachine machine;
    ParsedLine out;

    const ParsedLine& parse(std::string_view line, const Dialect& d = ncstudio_dialect()) {
        BlockParser p(d, vars, machine);
        p.parse(line, SourceLoc{"p.nc", 12, 1}, out);
        return out;
    }
    std::string error(std::string_view line, const Dialect& d = ncstudio_dialect()) {
        try {
            parse(line, d);
        } catch (const Error& e) {
            return e.what();
        }
        return "no error";
    }
};

}  // namespace

TEST_F(ParserFixture, SimpleMotionBlock) {
    const Block& b = parse("G1 X1.5 Y-2 Z.5 F100").block;
    ASSERT_EQ(b.g.size(), 1u);
    EXPECT_EQ(b.g[0], 10);
    EXPECT_EQ(b.get('X'), 1.5);
    EXPECT_EQ(b.get('Y'), -2.0);
    EXPECT_EQ(b.get('Z'), 0.5);
    EXPECT_EQ(b.get('F'), 100.0);
    EXPECT_FALSE(b.has('I'));
    EXPECT_EQ(b.col('Y'), 9);
    EXPECT_EQ(b.loc.line, 12);
    EXPECT_EQ(b.loc.col, 1);
}

TEST_F(ParserFixture, GCodesScaledByTen) {
    EXPECT_EQ(parse("G50.1 X0").block.g[0], 501);
    EXPECT_EQ(parse("G992 X0").block.g[0], 9920);
    EXPECT_EQ(parse("G54.1").block.g[0], 541);
    EXPECT_EQ(parse("G00").block.g[0], 0);
    EXPECT_EQ(parse("G0").block.g[0], 0);
    EXPECT_EQ(parse("G=1+2").block.g[0], 30);  // S1 §3.5 example 1: G3
    const Block& b = parse("G17G90 G00").block;
    EXPECT_EQ(b.g.size(), 3u);
    EXPECT_EQ(b.g[1], 900);
    EXPECT_EQ(b.g_col[1], 4);
}

TEST_F(ParserFixture, SeveralMCodesAndSequenceNumber) {
    const Block& b = parse("N0120 G49 X-80 Y-20 M05 M09 M30").block;
    ASSERT_TRUE(b.n);
    EXPECT_EQ(*b.n, 120);
    EXPECT_EQ(b.m.size(), 3u);
    EXPECT_TRUE(b.has_m(5) && b.has_m(9) && b.has_m(30));
    EXPECT_EQ(b.m_col[2], 29);
}

TEST_F(ParserFixture, SpacesBetweenLetterAndNumber) {
    const Block& b = parse("X-20 K 4").block;
    EXPECT_EQ(b.get('K'), 4.0);
    EXPECT_EQ(b.get('X'), -20.0);
}

TEST_F(ParserFixture, IntegerLiteralMask) {
    const Block& b = parse("X10 Y10. Z=3").block;
    EXPECT_TRUE(b.integer_literal_mask & (1u << letter_index('X')));
    EXPECT_FALSE(b.integer_literal_mask & (1u << letter_index('Y')));
    EXPECT_FALSE(b.integer_literal_mask & (1u << letter_index('Z')));
}

TEST_F(ParserFixture, ExpressionsAndAssignments) {
    EXPECT_EQ(parse("B=1+2;").block.get('B'), 3.0);
    EXPECT_NEAR(parse("G00 X3 Y5 Z=5+sin(5+abs(-8))").block.get('Z'), 5.420167037, 1e-9);
    vars.begin();
    const Block& b = parse("#1=4+log6 G01 X2 Y=#1").block;
    EXPECT_NEAR(b.get('Y'), 5.791759469, 1e-9);
    EXPECT_NEAR(*vars.numbered_if_set(1), 5.791759469, 1e-9);
    vars.rollback();  // the block's assignments are undone as a unit
    EXPECT_FALSE(vars.numbered_if_set(1));
    parse("#FC50=7 #2=#FC50*2");
    EXPECT_EQ(*vars.numbered_if_set(2), 14.0);
}

TEST_F(ParserFixture, IfGuardsTheRestOfTheBlock) {
    vars.set_numbered(1, 0, {});
    const ParsedLine& l = parse("N5 G90 IF(#1) G1 X5 #2=3");
    EXPECT_TRUE(l.if_false);
    EXPECT_EQ(*l.block.n, 5);
    EXPECT_EQ(l.block.g.size(), 1u);  // G90 before the IF stays
    EXPECT_FALSE(l.block.has('X'));
    EXPECT_FALSE(vars.numbered_if_set(2));  // assignments after a false IF do not run
    // A false IF does not evaluate the rest, so it cannot fail there …
    EXPECT_EQ(error("IF(0) X=1/0"), "no error");
    // … but its syntax is still checked.
    EXPECT_EQ(error("IF(0) X=foo(1)"), "p.nc:12:9: unknown function 'foo'");
    vars.set_fixed_cycle(13, 0, {});
    const Block& t = parse("IF(!#FC13)G90 G65 P786").block;
    EXPECT_EQ(t.g.size(), 2u);
    EXPECT_EQ(t.get('P'), 786.0);
    EXPECT_FALSE(out.if_false);
    EXPECT_EQ(parse("IF(1==1 && 2>1) X1").block.get('X'), 1.0);
}

TEST_F(ParserFixture, NcStudioKeywords) {
    const Block& b = parse("G906 PLC[04] LEVEL1 P1000;").block;
    EXPECT_EQ(*b.kw.plc, 4);
    EXPECT_EQ(*b.kw.level, 1);
    EXPECT_EQ(b.get('P'), 1000.0);
    EXPECT_EQ(*parse("M901 PLC=2+3 LEVEL0").block.kw.plc, 5);
    const Block& g = parse("G904 FX100 PX[3] LX1 FY=-50 PY=2 LY0 X10").block;
    EXPECT_EQ(*g.kw.f_axis[0], 100.0);
    EXPECT_EQ(*g.kw.p_axis[0], 3);
    EXPECT_EQ(*g.kw.l_axis[0], 1);
    EXPECT_EQ(*g.kw.f_axis[1], -50.0);
    EXPECT_EQ(*g.kw.p_axis[1], 2);
    EXPECT_EQ(*g.kw.l_axis[1], 0);
    EXPECT_FALSE(g.kw.f_axis[2]);
    EXPECT_EQ(g.get('X'), 10.0);
    const Block& l = parse("G916 PX[00000]LX0").block;
    EXPECT_EQ(*l.kw.p_axis[0], 0);
    EXPECT_EQ(*l.kw.l_axis[0], 0);
}

TEST_F(ParserFixture, Messages) {
    EXPECT_EQ(*parse("M801 MSG\xE2\x80\x9CHello\xE2\x80\x9D ' pass it on").block.msg, "Hello");
    EXPECT_EQ(*parse("M801\xE2\x80\x9DInformation\xE2\x80\x9D").block.msg, "Information");
}

TEST_F(ParserFixture, LabelsAndProgramNames) {
    EXPECT_TRUE(parse("O9001").is_label);
    EXPECT_EQ(out.label_number, 9001);
    EXPECT_TRUE(parse("O1000      ' coolant and tool change").is_label);
    EXPECT_TRUE(parse("O\"frame_2\"").is_label);
    EXPECT_EQ(out.label_name, "frame_2");
    const ParsedLine& c = parse("G65 P\"frame_2\" L2");
    EXPECT_EQ(*c.p_name, "frame_2");
    EXPECT_EQ(c.block.get('L'), 2.0);
    EXPECT_FALSE(c.block.has('P'));
}

TEST_F(ParserFixture, BlockDeleteMark) {
    EXPECT_TRUE(parse("/G1 X1").block_delete);
    EXPECT_EQ(out.block.get('X'), 1.0);
}

TEST_F(ParserFixture, EmptyAndCommentLines) {
    EXPECT_TRUE(parse("").block.empty());
    EXPECT_TRUE(parse("   ' only a comment").block.empty());
    EXPECT_TRUE(parse("#1=2").block.empty());
}

TEST_F(ParserFixture, ErrorDuplicateWord) {
    EXPECT_EQ(error("G1 X1 X2"), "p.nc:12:7: word X appears twice in one block");
}
TEST_F(ParserFixture, ErrorMissingValue) {
    EXPECT_EQ(error("G1 X Y2"), "p.nc:12:6: expected a number or '=' after X");
    EXPECT_EQ(error("G1 X"), "p.nc:12:4: expected a number or '=' after X");
    EXPECT_EQ(error("X#1"), "p.nc:12:2: expected a number or '=' after X");
}
TEST_F(ParserFixture, ErrorSpaceInsideSignedNumber) {
    EXPECT_EQ(error("X- 20"), "p.nc:12:4: space between a sign and its number");
}
TEST_F(ParserFixture, ErrorNumberWithoutAddress) {
    EXPECT_EQ(error("G1 X1.5.5"), "p.nc:12:8: number '.5' without an address letter");
}
TEST_F(ParserFixture, ErrorStrayOperator) {
    EXPECT_EQ(error("G1 *X1"), "p.nc:12:4: unexpected '*' where a word should start");
}
TEST_F(ParserFixture, ErrorUnknownWord) {
    EXPECT_EQ(error("G1 XY10"), "p.nc:12:4: unknown word 'XY'");
    // The NcStudio dialect has no GOTO (IF-03).
    EXPECT_EQ(error("IF(1) GOTO 10"), "p.nc:12:7: unknown word 'GOTO'");
}
TEST_F(ParserFixture, ErrorGCodeWithTwoDecimals) {
    EXPECT_EQ(error("G50.15"), "p.nc:12:1: G code G50.15 has more than one decimal");
}
TEST_F(ParserFixture, ErrorNegativeCodes) {
    EXPECT_EQ(error("G-1"), "p.nc:12:1: G code out of range");
    EXPECT_EQ(error("M-3"), "p.nc:12:1: M code must not be negative");
    EXPECT_EQ(error("M3.5"), "p.nc:12:1: M code must be an integer, got 3.5");
}
TEST_F(ParserFixture, ErrorNegativeSequenceNumber) {
    EXPECT_EQ(error("N-1 G1"), "p.nc:12:1: sequence number N must not be negative");
}
TEST_F(ParserFixture, ErrorTooManyMCodes) {
    EXPECT_EQ(error("M1 M1 M1 M1 M1 M1 M1 M1 M1 M1 M1 M1 M1 M1 M1 M1 M1"),
              "p.nc:12:49: too many M codes in one block");
}
TEST_F(ParserFixture, ErrorProgramNameAndNumber) {
    EXPECT_EQ(error("G65 P\"a\" P2"), "p.nc:12:10: word P appears twice in one block");
    EXPECT_EQ(error("G65 P2 P\"a\""), "p.nc:12:8: word P appears twice in one block");
}
TEST_F(ParserFixture, ErrorAssignToOutOfRangeVariable) {
    EXPECT_EQ(error("#0=1"), "p.nc:12:1: variable #0 is out of range (#1…#999)");
}
TEST_F(ParserFixture, ErrorStrictSpaceAfterEquals) {
    Dialect strict = ncstudio_dialect();
    strict.tolerant_expr_spaces = false;
    EXPECT_EQ(error("X= 5", strict), "p.nc:12:4: spaces are not allowed inside an expression");
    EXPECT_EQ(error("X= 5"), "no error");
}
TEST_F(ParserFixture, ErrorTwoSequenceNumbers) {
    EXPECT_EQ(error("N1 N2"), "p.nc:12:4: a block can have only one sequence number N");
}
TEST_F(ParserFixture, ErrorTooManyGCodes) {
    EXPECT_EQ(error("G1 G1 G1 G1 G1 G1 G1 G1 G1 G1 G1 G1 G1 G1 G1 G1 G1"),
              "p.nc:12:49: too many G codes in one block");
}
TEST_F(ParserFixture, ErrorAssignToNamedParameter) {
    EXPECT_EQ(error("#SAFEHEIGHT=5"), "p.nc:12:1: named parameter #SAFEHEIGHT is read-only");
}
TEST_F(ParserFixture, ErrorVariableWithoutAssignment) {
    EXPECT_EQ(error("#1 G1"), "p.nc:12:1: #1 on its own is not a word (did you mean #1=…?)");
}
TEST_F(ParserFixture, ErrorAssignmentWithoutExpression) {
    EXPECT_EQ(error("#1="), "p.nc:12:4: expression expected after '='");
    EXPECT_EQ(error("X="), "p.nc:12:3: expression expected after '='");
}
TEST_F(ParserFixture, ErrorIfSyntax) {
    EXPECT_EQ(error("IF #1 X1"), "p.nc:12:4: IF must be followed by '(' condition ')'");
    EXPECT_EQ(error("IF(1 X1"), "p.nc:12:6: expected ')' to close the IF condition");
}
TEST_F(ParserFixture, ErrorPlcAddress) {
    EXPECT_EQ(error("M901 PLC[4.5] LEVEL1"), "p.nc:12:10: PLC[…] needs an integer PLC address");
    EXPECT_EQ(error("M901 PLC[4 LEVEL1"), "p.nc:12:12: expected ']' after the PLC address");
    EXPECT_EQ(error("M901 PLC=1.5"), "p.nc:12:6: PLC address must be an integer, got 1.5");
}
TEST_F(ParserFixture, ErrorDuplicateKeyword) {
    EXPECT_EQ(error("M901 PLC[1] PLC[2]"), "p.nc:12:13: word PLC appears twice in one block");
}
TEST_F(ParserFixture, ErrorMsgWithoutString) {
    EXPECT_EQ(error("M801 MSG 5"), "p.nc:12:10: MSG must be followed by a \"string\"");
}
TEST_F(ParserFixture, ErrorTwoMessages) {
    EXPECT_EQ(error("M801 MSG \"a\" \"b\""),
              "p.nc:12:14: a block can carry only one message string");
}
TEST_F(ParserFixture, ErrorLabelNotAlone) {
    EXPECT_EQ(error("O9001 G1 X1"),
              "p.nc:12:7: a subprogram label O… must stand alone on its line");
    EXPECT_EQ(error("G1 O9001"), "p.nc:12:4: a subprogram label O… must stand alone on its line");
}
TEST_F(ParserFixture, ErrorLabelSyntax) {
    EXPECT_EQ(error("O12.5"), "p.nc:12:1: O must be followed by a program number or a \"name\"");
    EXPECT_EQ(error("O\"a b\""),
              "p.nc:12:2: subprogram name 'a b' may only contain letters, digits and '_'");
    EXPECT_EQ(error("O\"\""), "p.nc:12:2: empty subprogram name");
}

// EX-32 (S1 §3.3): the arc examples' start point is only in a figure and |IJ| ≠ R, so FEATURES
// asks for a syntax test only: the words parse with the written values.
TEST_F(ParserFixture, Ex32ArcExamplesParse) {
    const Block& a = parse("G17 G90 G02 X20 Y10 I-2 J-14", ncstudio_v54_dialect()).block;
    EXPECT_EQ(a.g.size(), 3u);
    EXPECT_EQ(a.get('I'), -2.0);
    EXPECT_EQ(a.get('J'), -14.0);
    const Block& r = parse("G02 X20 Y10 R12", ncstudio_v54_dialect()).block;
    EXPECT_EQ(r.get('R'), 12.0);
    const Block& b = parse("G03 X10 Y22 I-12 J-2", ncstudio_v54_dialect()).block;
    EXPECT_EQ(b.get('X'), 10.0);
    EXPECT_EQ(b.get('J'), -2.0);
}
