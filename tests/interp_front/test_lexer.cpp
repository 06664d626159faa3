#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "interp/expr.hpp"
#include "interp/lexer.hpp"

using namespace interp;

namespace {

std::vector<Token> lex(std::string_view line, const Dialect& d = ncstudio_dialect()) {
    std::vector<Token> out;
    Lexer(d).lex(line, SourceLoc{"t.nc", 7, 0}, out);
    return out;
}

// Compact description: W:G N:1 W:X N:100 ... E
std::string shape(const std::vector<Token>& toks) {
    std::string s;
    for (const Token& t : toks) {
        if (!s.empty()) s += ' ';
        switch (t.kind) {
            case Tok::End:
                s += "E";
                break;
            case Tok::Word:
                s += "W:" + std::string(t.text);
                break;
            case Tok::Number:
                s += "N:" + std::string(t.text);
                break;
            case Tok::Var:
                s += "V:" + std::string(t.text);
                break;
            case Tok::String:
                s += "S:" + std::string(t.text);
                break;
            case Tok::Op:
                s += "O:" + std::string(op_text(t.op));
                break;
        }
    }
    return s;
}

std::string lex_error(std::string_view line, const Dialect& d = ncstudio_dialect()) {
    try {
        lex(line, d);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST(Lexer, PackedWords) {
    EXPECT_EQ(shape(lex("N20G90G00X25Y30")), "W:N N:20 W:G N:90 W:G N:00 W:X N:25 W:Y N:30 E");
    EXPECT_EQ(shape(lex("G91G65 P9999")), "W:G N:91 W:G N:65 W:P N:9999 E");
}

TEST(Lexer, NumberForms) {
    auto t = lex("X0. F.8 Z100. R50.25 Y007");
    ASSERT_EQ(t.size(), 11u);
    EXPECT_EQ(t[1].number, 0.0);
    EXPECT_TRUE(t[1].has_point);
    EXPECT_EQ(t[3].number, 0.8);
    EXPECT_EQ(t[5].number, 100.0);
    EXPECT_EQ(t[7].number, 50.25);
    EXPECT_EQ(t[9].number, 7.0);
    EXPECT_FALSE(t[9].has_point);
    // Long literals take the slow, still exact, path.
    auto l = lex("X1234567890.1234567");
    EXPECT_DOUBLE_EQ(l[1].number, 1234567890.1234567);
}

TEST(Lexer, SpacesBetweenLetterAndValueAreKept) {
    auto t = lex("X-20 K 4");
    EXPECT_EQ(shape(t), "W:X O:- N:20 W:K N:4 E");
    EXPECT_TRUE(t[4].space_before);
    EXPECT_EQ(t[4].col, 8);
}

TEST(Lexer, CommentsAndBlockEnd) {
    EXPECT_EQ(shape(lex("G00 X3 Y5      ' rapid to X3, Y5")), "W:G N:00 W:X N:3 W:Y N:5 E");
    EXPECT_EQ(shape(lex("X25'hole 2")), "W:X N:25 E");
    EXPECT_EQ(shape(lex("B=1+2;")), "W:B O:= N:1 O:+ N:2 E");
    EXPECT_EQ(shape(lex("G918; ' clear latch flags")), "W:G N:918 E");
    // S1 prints the comment quote as U+2019.
    EXPECT_EQ(shape(lex("G903 G01 X10 F600;\xE2\x80\x99 force")),
              "W:G N:903 W:G N:01 W:X N:10 W:F N:600 E");
    EXPECT_EQ(shape(lex("G905 G01 X1\xE2\x80\x99 c")), "W:G N:905 W:G N:01 W:X N:1 E");
    // Parenthesised comments outside expressions (LEX-34), nested (LEX-31).
    EXPECT_EQ(shape(lex("(c(c) X100) Y100")), "W:Y N:100 E");
    EXPECT_EQ(shape(lex("G1 X1 (move) Y2")), "W:G N:1 W:X N:1 W:Y N:2 E");
}

TEST(Lexer, ParenthesesAfterOperatorsAndFunctionsAreExpressions) {
    EXPECT_EQ(shape(lex("Z=5+sin(5+abs(-8))")),
              "W:Z O:= N:5 O:+ W:sin O:( N:5 O:+ W:abs O:( O:- N:8 O:) O:) E");
    EXPECT_EQ(shape(lex("IF(!#FC13)G90")), "W:IF O:( O:! V:FC13 O:) W:G N:90 E");
    EXPECT_EQ(
        shape(lex("L=INT(ABS(#FC4-#FC3) /ABS (#FC5)) -1")),
        "W:L O:= W:INT O:( W:ABS O:( V:FC4 O:- V:FC3 O:) O:/ W:ABS O:( V:FC5 O:) O:) O:- N:1 E");
}

TEST(Lexer, VariablesAndNamedParameters) {
    EXPECT_EQ(shape(lex("#1=30")), "V:1 O:= N:30 E");
    EXPECT_EQ(shape(lex("X=#CURMACHPOS.X Y=#ctp_pos.y")),
              "W:X O:= V:CURMACHPOS.X W:Y O:= V:ctp_pos.y E");
    // S0 §4.1.1 prints "#CTP_POS. X" with a space after the dot.
    auto t = lex("X=#CTP_POS. X Y1");
    EXPECT_EQ(shape(t), "W:X O:= V:CTP_POS. X W:Y N:1 E");
    EXPECT_EQ(shape(lex("#SSINPORT12")), "V:SSINPORT12 E");
}

TEST(Lexer, StringsWithPlainAndTypographicQuotes) {
    EXPECT_EQ(shape(lex("M801 MSG \"Hello\"")), "W:M N:801 W:MSG S:Hello E");
    EXPECT_EQ(shape(lex("M801 MSG\xE2\x80\x9CHello World\xE2\x80\x9D")),
              "W:M N:801 W:MSG S:Hello World E");
    EXPECT_EQ(shape(lex("M801\xE2\x80\x9DInformation\xE2\x80\x9D")), "W:M N:801 S:Information E");
    EXPECT_EQ(shape(lex("O\"frame\"")), "W:O S:frame E");
    EXPECT_EQ(shape(lex("M801 MSG \"it's; fine\"")), "W:M N:801 W:MSG S:it's; fine E");
}

TEST(Lexer, KeywordsAndBrackets) {
    EXPECT_EQ(shape(lex("G916 PX[00000]LX0")), "W:G N:916 W:PX O:[ N:00000 O:] W:LX N:0 E");
    EXPECT_EQ(shape(lex("G906 PLC[04] LEVEL1 P1000")),
              "W:G N:906 W:PLC O:[ N:04 O:] W:LEVEL N:1 W:P N:1000 E");
}

TEST(Lexer, OperatorSetsPerDialect) {
    EXPECT_EQ(shape(lex("#1=#2||#3&&#4==1")), "V:1 O:= V:2 O:|| V:3 O:&& V:4 O:== N:1 E");
    EXPECT_EQ(shape(lex("#1=|-2|^2", ncstudio_v54_dialect())), "V:1 O:= O:| O:- N:2 O:| O:^ N:2 E");
    EXPECT_EQ(shape(lex("#1=#2>=1<=2!=3")), "V:1 O:= V:2 O:>= N:1 O:<= N:2 O:!= N:3 E");
}

TEST(Lexer, TapeMarkerLineIsEmpty) {
    EXPECT_EQ(shape(lex("%")), "E");
    EXPECT_EQ(shape(lex("  % ")), "E");
    EXPECT_EQ(lex_error("G1 %"), "t.nc:7:4: unexpected character '%'");
}

TEST(Lexer, ColumnsAreOneBased) {
    auto t = lex("  G1  X5");
    EXPECT_EQ(t[0].col, 3);
    EXPECT_EQ(t[2].col, 7);
}

TEST(LexerErrors, UnexpectedCharacter) {
    EXPECT_EQ(lex_error("G1 X1 @"), "t.nc:7:7: unexpected character '@'");
}

TEST(LexerErrors, NonAsciiOutsideComment) {
    EXPECT_EQ(lex_error("G1 \xE5\xAD\x94"),
              "t.nc:7:4: unexpected byte 0xE5 (non-ASCII text belongs in a ' comment or a string)");
}

TEST(LexerErrors, UnterminatedString) {
    EXPECT_EQ(lex_error("M801 MSG \"abc"),
              "t.nc:7:10: unterminated string (missing closing quote)");
}

TEST(LexerErrors, UnclosedParenComment) {
    EXPECT_EQ(lex_error("G1 X1 (oops"), "t.nc:7:7: unclosed '(' comment");
}

TEST(LexerErrors, HashWithoutName) {
    EXPECT_EQ(lex_error("#=5"), "t.nc:7:1: expected a variable number or parameter name after '#'");
}

TEST(LexerErrors, NumberOutOfRange) {
    EXPECT_EQ(lex_error("G1 X" + std::string(400, '9')), "t.nc:7:5: number out of range");
}

TEST(LexerErrors, ParenCommentsDisabledByDialect) {
    Dialect d = ncstudio_dialect();
    d.paren_comments = false;
    EXPECT_EQ(lex_error("G1 X1 (c)", d), "t.nc:7:7: '(' comments are not allowed in this dialect");
}

TEST(LexerErrors, SingleBarOutsideV54) {
    EXPECT_EQ(lex_error("#1=|2|"), "t.nc:7:4: unexpected character '|'");
}

// Columns count characters, not bytes: each Chinese character below is 3 bytes of UTF-8.
TEST(Lexer, ColumnsCountCharactersAfterChineseText) {
    auto t = lex("G00 X1 (快速移动) G33");
    ASSERT_EQ(t.size(), 7u);
    EXPECT_EQ(t[4].text, "G");
    EXPECT_EQ(t[4].col, 15);  // bytes would say 23
    auto m = lex("M801 MSG \"加工完成\" X2");
    EXPECT_EQ(m[4].text, "X");
    EXPECT_EQ(m[4].col, 17);  // bytes would say 25
}

TEST(Lexer, ErrorColumnAfterChineseComment) {
    EXPECT_EQ(lex_error("(注释) X1 $"), "t.nc:7:9: unexpected character '$'");
}

// The token cursor reads its current token without a bounds check; that is safe only because
// every lexed line ends with exactly one Tok::End and next() never moves past it.
TEST(Lexer, EveryLineEndsWithOneEndTokenTheCursorStopsAt) {
    for (std::string_view line : {"", "   ", "; only a comment", "G1 X1.5 Y-2", "(c) #1=[2*3]", "%",
                                  "N10 G0 X0 ' quote comment"}) {
        const std::vector<Token> t = lex(line);
        ASSERT_FALSE(t.empty()) << line;
        EXPECT_EQ(t.back().kind, Tok::End) << line;
        for (std::size_t i = 0; i + 1 < t.size(); ++i) EXPECT_NE(t[i].kind, Tok::End) << line;
        TokenCursor cur{&t, 0};
        for (std::size_t i = 0; i < t.size() + 3; ++i) cur.next();
        EXPECT_EQ(cur.pos, t.size() - 1) << line;
        EXPECT_EQ(cur.peek().kind, Tok::End) << line;
        EXPECT_TRUE(cur.at_end()) << line;
    }
}
