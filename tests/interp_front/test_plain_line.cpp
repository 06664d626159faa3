// The block parser's fast path for plain lines (Lexer::lex_plain) must give exactly what the
// general path (lexer + token walk) gives: the same block, or the same error. A ';' appended to
// a line ends its executable text, changes nothing it means and keeps it off the fast path, so
// parse(line) and parse(line + ";") compare the two paths on any line.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "fakes.hpp"
#include "interp/lexer.hpp"
#include "interp/parser.hpp"

using namespace interp;

namespace {

// Everything the parser hands on, as text, or the error it threw.
std::string parse_result(const Dialect& d, std::string_view line) {
    Variables vars;
    test::FakeMachine machine;
    BlockParser parser(d, vars, machine);
    ParsedLine out;
    try {
        parser.parse(line, SourceLoc{"p.nc", 7, 1}, out);
    } catch (const Error& e) {
        return std::string("error: ") + e.what();
    }
    const Block& b = out.block;
    std::string s = "col " + std::to_string(b.loc.col) + " line " + std::to_string(b.loc.line);
    for (std::size_t i = 0; i < b.g.size(); ++i)
        s += " G" + std::to_string(b.g[i]) + "@" + std::to_string(b.g_col[i]);
    for (std::size_t i = 0; i < b.m.size(); ++i)
        s += " M" + std::to_string(b.m[i]) + "@" + std::to_string(b.m_col[i]);
    if (b.n) s += " N" + std::to_string(*b.n);
    for (int i = 0; i < 26; ++i) {
        if (!b.words[i]) continue;
        char buf[64];
        // %a: the exact bits, so a value computed differently by the two paths shows.
        std::snprintf(buf, sizeof buf, " %c%a@%d", 'A' + i, *b.words[i], b.word_col[i]);
        s += buf;
    }
    s += " int " + std::to_string(b.integer_literal_mask) + " set " +
         std::to_string(out.letters_set);
    s += out.is_label ? " label" : "";
    s += out.block_delete ? " delete" : "";
    s += out.if_false ? " if-false" : "";
    s += out.p_name ? " pname " + *out.p_name : "";
    s += b.msg ? " msg " + *b.msg : "";
    s += b.kw.empty() ? "" : " keywords";
    return s;
}

bool plain(std::string_view line) {
    PlainLine words;
    return Lexer(ncstudio_dialect()).lex_plain(line, words);
}

}  // namespace

TEST(PlainLine, AcceptsCamLinesOnly) {
    EXPECT_TRUE(plain("G3 X-10.000 Y0 Z-1.000 I-10.000 J0"));
    EXPECT_TRUE(plain("G1X10Y.5F2000"));
    EXPECT_TRUE(plain("  n10 g1 x+1. "));
    EXPECT_TRUE(plain(""));
    EXPECT_TRUE(plain("X -5"));  // space between the letter and its sign is allowed
    EXPECT_FALSE(plain("G1 X- 5"));
    EXPECT_FALSE(plain("G1 X1 (comment)"));
    EXPECT_FALSE(plain("G1 X1 ;"));
    EXPECT_FALSE(plain("G1 X=1+2"));
    EXPECT_FALSE(plain("O1000"));
    EXPECT_FALSE(plain("/G1 X1"));
    EXPECT_FALSE(plain("IF(1) G1"));
    EXPECT_FALSE(plain("#1=2"));
    EXPECT_FALSE(plain("G1 X"));
    EXPECT_FALSE(plain("G1 X1.2.3"));
    EXPECT_FALSE(plain("1"));
    EXPECT_FALSE(plain("M801 \"text\""));
}

TEST(PlainLine, WordsAsWritten) {
    PlainLine w;
    ASSERT_TRUE(Lexer(ncstudio_dialect()).lex_plain(" g2x-1.5 Y2", w));
    ASSERT_EQ(w.count, 3);
    EXPECT_EQ(w.words[0].letter, 'g');
    EXPECT_EQ(w.words[0].col, 2);
    EXPECT_TRUE(w.words[0].integer_literal);
    EXPECT_EQ(w.words[0].value, 2.0);
    EXPECT_EQ(w.words[1].letter, 'x');
    EXPECT_EQ(w.words[1].col, 4);
    EXPECT_FALSE(w.words[1].integer_literal);
    EXPECT_EQ(w.words[1].value, -1.5);
    EXPECT_EQ(w.words[2].col, 10);
}

TEST(PlainLine, SameBlockOrErrorAsTheGeneralPath) {
    // Pieces of lines: letters, literals, and what the fast path must leave to the general path
    // (keywords, expressions, comments, labels, strings, stray bytes, out-of-range numbers).
    const std::vector<std::string> letters = {"G", "X", "Y", "Z", "I", "J", "R",  "F",
                                              "M", "N", "O", "P", "g", "x", "GX", "IF"};
    const std::vector<std::string> numbers = {"1",
                                              "3",
                                              "10.000",
                                              ".5",
                                              "0.",
                                              "1.2",
                                              "12345678901234567",
                                              "3.25",
                                              "0",
                                              "2.55",
                                              "17.1",
                                              "1e5",
                                              "99999999999",
                                              "1000000000000000000000000000",
                                              "1" + std::string(400, '0')};
    const std::vector<std::string> others = {" ", "\t", "-", "+",     ".",  "=", "(",
                                             ")", ";",  "/", "\"a\"", "#1", "[", "*"};
    std::vector<std::string> pieces = letters;
    pieces.insert(pieces.end(), numbers.begin(), numbers.end());
    pieces.insert(pieces.end(), others.begin(), others.end());
    std::mt19937 rng(20261121);
    const auto pick = [&rng](const std::vector<std::string>& from) -> const std::string& {
        return from[std::uniform_int_distribution<std::size_t>(0, from.size() - 1)(rng)];
    };
    const Dialect* dialects[] = {&ncstudio_dialect(), &ncstudio_v54_dialect(),
                                 &ncstudio_c_logic_dialect()};
    int fast = 0, fast_ok = 0, fast_errors = 0;
    for (int trial = 0; trial < 40000; ++trial) {
        std::string line;
        const int n = static_cast<int>(rng() % 12);
        if (trial % 3 == 0) {
            for (int k = 0; k < n; ++k) line += pick(pieces);
        } else {
            // Shaped like words (letter, optional space or sign, literal), so the fast path is
            // taken often, with now and then one odd piece.
            for (int k = 0; k < n; ++k) {
                line += pick(letters);
                const unsigned r = rng() % 8;
                line += r == 0 ? "-" : r == 1 ? " " : r == 2 ? "+" : r == 3 ? " -" : "";
                line += pick(numbers);
                if (rng() % 3 == 0) line += " ";
                if (rng() % 40 == 0) line += pick(others);
            }
        }
        ASSERT_FALSE(plain(line + ";")) << line;
        const bool is_plain = plain(line);
        for (const Dialect* d : dialects) {
            const std::string a = parse_result(*d, line);
            ASSERT_EQ(a, parse_result(*d, line + ";")) << "line '" << line << "'";
            if (is_plain && d == dialects[0]) {
                ++fast;
                (a.rfind("error", 0) == 0 ? fast_errors : fast_ok)++;
            }
        }
    }
    // The comparison means something only if the fast path ran often, on good and bad lines.
    EXPECT_GT(fast_ok, 3000);
    EXPECT_GT(fast_errors, 300);
    EXPECT_GT(fast, 6000);
}
