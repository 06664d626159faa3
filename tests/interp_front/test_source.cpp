#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "interp/source.hpp"

using namespace interp;

namespace {

std::string temp_path(const std::string& tag) {
    return ::testing::TempDir() + "ifront_src_" + tag + "_" + std::to_string(::getpid()) + ".nc";
}

std::vector<std::string> all_lines(Source& s) {
    std::vector<std::string> out;
    std::string_view line;
    while (s.next_line(line)) out.emplace_back(line);
    return out;
}

}  // namespace

TEST(Source, SplitsLinesAndStripsCarriageReturns) {
    auto s = Source::from_string("t.nc", "G0 X1\r\n\nG1 Y2\nM30");
    EXPECT_EQ(all_lines(*s), (std::vector<std::string>{"G0 X1", "", "G1 Y2", "M30"}));
    EXPECT_EQ(s->line_number(), 4);
}

TEST(Source, IndexesNumberedAndNamedLabels) {
    auto s =
        Source::from_string("t.nc", "G0 X0\nM30\nO9001\nG1 X1\nM17\n  o\"Frame_1\" ' c\nM17\n");
    ASSERT_TRUE(s->find_label(9001));
    EXPECT_EQ(s->find_label(9001)->pos.line, 3);
    ASSERT_TRUE(s->find_label("frame_1"));  // names are case-insensitive
    EXPECT_EQ(s->find_label("FRAME_1")->pos.line, 6);
    EXPECT_EQ(s->find_label("FRAME_1")->col, 3);
    EXPECT_FALSE(s->find_label(9002));
    EXPECT_EQ(s->label_count(), 2u);
    // Indexing must leave the source at its start.
    std::string_view first;
    ASSERT_TRUE(s->next_line(first));
    EXPECT_EQ(first, "G0 X0");
}

TEST(Source, DuplicateLabelIsAnError) {
    try {
        Source::from_string("dup.nc", "O1\nM17\nO1\nM17\n");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "dup.nc:3:1: subprogram O1 is defined twice (first at line 1)");
    }
}

TEST(Source, DuplicateNamedLabelIsAnError) {
    try {
        Source::from_string("dup.nc", "O\"a\"\nM17\nO\"A\"\nM17\n");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "dup.nc:3:1: subprogram O\"A\" is defined twice (first at line 1)");
    }
}

TEST(Source, MissingFileNamesTheFile) {
    try {
        Source::open_file("/nonexistent/ifront/prog.nc");
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(
            std::string(e.what()).rfind("/nonexistent/ifront/prog.nc:0:0: cannot open program", 0),
            0u)
            << e.what();
    }
}

TEST(Source, OverlongLineIsAnErrorAndReadingContinues) {
    const std::string path = temp_path("overlong");
    {
        std::ofstream f(path, std::ios::binary);
        f << "G1 X1\n" << std::string(3 * 1024 * 1024, 'X') << "\nO5\nG1 X3\n";
    }
    auto s = Source::open_file(path);
    EXPECT_TRUE(s->find_label(5));  // indexing steps over the long line
    std::string_view line;
    ASSERT_TRUE(s->next_line(line));
    EXPECT_EQ(line, "G1 X1");
    try {
        s->next_line(line);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), path + ":2:1: line is longer than 1 MiB");
    }
    ASSERT_TRUE(s->next_line(line));
    EXPECT_EQ(line, "O5");
    EXPECT_EQ(s->line_number(), 3);
    ::unlink(path.c_str());
}

// A file several windows long, with a line longer than the window, read in order and after
// seeks both inside and outside the current window.
TEST(Source, StreamsLargeFileAcrossWindowsAndSeeks) {
    const std::string path = temp_path("large");
    const std::string long_line = "G1 X" + std::string(100000, '1');
    {
        std::ofstream f(path, std::ios::binary);
        for (int i = 1; i <= 30000; ++i) {
            if (i == 15000)
                f << long_line << "\n";
            else if (i == 29000)
                f << "O777\n";
            else
                f << "N" << i << " G1 X" << i << "\n";
        }
    }
    auto s = Source::open_file(path);
    ASSERT_TRUE(s->find_label(777));
    EXPECT_EQ(s->find_label(777)->pos.line, 29000);
    std::string_view line;
    SourcePos at10{}, at20000{};
    int n = 0;
    while (s->next_line(line)) {
        ++n;
        ASSERT_EQ(s->line_number(), n);
        if (n == 10) at10 = s->line_start();
        if (n == 20000) at20000 = s->line_start();
        if (n == 15000) {
            EXPECT_EQ(line.size(), long_line.size());
        } else if (n != 29000) {
            ASSERT_EQ(line, "N" + std::to_string(n) + " G1 X" + std::to_string(n));
        }
    }
    EXPECT_EQ(n, 30000);
    s->seek(at10);  // far outside the current window
    ASSERT_TRUE(s->next_line(line));
    EXPECT_EQ(line, "N10 G1 X10");
    EXPECT_EQ(s->line_number(), 10);
    s->seek(at20000);
    ASSERT_TRUE(s->next_line(line));
    EXPECT_EQ(line, "N20000 G1 X20000");
    s->seek(s->find_label(777)->pos);
    ASSERT_TRUE(s->next_line(line));
    EXPECT_EQ(line, "O777");
    ::unlink(path.c_str());
}

// LEX-07: duplicate sequence numbers are allowed but reported; each O label starts a new scope.
TEST(SourceScan, DuplicateSequenceNumbersPerProgram) {
    auto s = Source::from_string("d.nc", "N10 G0\nN20\n N10 X1\nO100\nN10\nN20\n/N20\nM17\n");
    const auto& d = s->duplicate_sequences();
    ASSERT_EQ(d.size(), 2u);
    EXPECT_EQ(d[0].n, 10);
    EXPECT_EQ(d[0].line, 3);
    EXPECT_EQ(d[0].col, 2);
    EXPECT_EQ(d[1].n, 20);
    EXPECT_EQ(d[1].line, 7);
    EXPECT_EQ(d[1].col, 2);
}

// LEX-07: the whole range the parser accepts for N (to 9e15) is checked, not only the bitmap's
// 2^22; each program scope starts afresh there too.
TEST(SourceScan, DuplicateLargeSequenceNumbers) {
    auto s = Source::from_string("d.nc",
                                 "N4194304\nN4194303\nN0004194304 X1\nN9000000000000000\n"
                                 "N9000000000000000\nO7\nN4194304\nN4194305\nM17\n");
    const auto& d = s->duplicate_sequences();
    ASSERT_EQ(d.size(), 2u);
    EXPECT_EQ(d[0].n, 4194304);
    EXPECT_EQ(d[0].line, 3);
    EXPECT_EQ(d[0].col, 1);
    EXPECT_EQ(d[1].n, 9000000000000000);
    EXPECT_EQ(d[1].line, 5);
    // Past the parser's range an N is an error of its own, never a duplicate.
    auto big = Source::from_string("b.nc", "N99999999999999999\nN99999999999999999\n");
    EXPECT_TRUE(big->duplicate_sequences().empty());
}
