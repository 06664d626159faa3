// The canonical stream's decoder refuses every malformed record sequence with its own message,
// naming the record by its number in the stream. The sequences are an encoder's records for
// `M801 "hello"` (file record, its name, the command, its text) with one thing broken; the
// record layout is the one canon_wire.hpp documents (word 0 = type | index << 8 |
// continuations << 24).
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "interp/canon.hpp"
#include "interp/canon_wire.hpp"

namespace interp {
namespace {

constexpr std::uint64_t kTypeMask = 0xff;
constexpr std::uint64_t kIndexMask = std::uint64_t{0xffff} << 8;

std::vector<wire::Record> hello_records() {
    wire::Encoder enc;
    std::vector<wire::Record> records;
    enc.command(Canon{SourceLoc{"f.ngc", 3, 1}, canon::Message{"hello"}}, records);
    return records;
}

// Feeds `records` to a fresh decoder; the error text, or "no error".
std::string error_of(const std::vector<wire::Record>& records) {
    wire::Decoder dec;
    try {
        for (const auto& r : records) dec.feed(r);
    } catch (const wire::Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(CanonWireErrors, TheUnbrokenSequenceDecodes) {
    const auto records = hello_records();
    ASSERT_EQ(records.size(), 4u);
    wire::Decoder dec;
    wire::Decoder::Item last = wire::Decoder::Item::None;
    for (const auto& r : records) last = dec.feed(r);
    ASSERT_EQ(last, wire::Decoder::Item::Command);
    EXPECT_EQ(dec.command().loc.file, "f.ngc");
    EXPECT_EQ(std::get<canon::Message>(dec.command().cmd).text, "hello");
}

TEST(CanonWireErrors, CommandBeforeItsFileIsAnnounced) {
    const auto r = hello_records();
    EXPECT_EQ(error_of({r[2]}),
              "canonical stream, record 1: command names file id 0, never announced");
}

TEST(CanonWireErrors, RecordWhereTextMustContinue) {
    const auto r = hello_records();
    EXPECT_EQ(error_of({r[0], r[1], r[2], r[2]}),
              "canonical stream, record 4: expected 1 more text record(s), got a record of type 1");
}

TEST(CanonWireErrors, EndRecordCuttingACommandShort) {
    const auto r = hello_records();
    wire::Encoder enc;
    std::vector<wire::Record> end;
    enc.end("", end);
    EXPECT_EQ(error_of({r[0], r[1], r[2], end.at(0)}),
              "canonical stream, record 4: expected 1 more text record(s), got a record of type 4");
}

TEST(CanonWireErrors, TextRecordWithNothingBeforeIt) {
    const auto r = hello_records();
    EXPECT_EQ(error_of({r[1]}),
              "canonical stream, record 1: a text record with no command or file before it");
}

TEST(CanonWireErrors, UnknownRecordTypes) {
    auto r = hello_records();
    wire::Record zero{};  // what a stream read past its writes would hold
    EXPECT_EQ(error_of({zero}), "canonical stream, record 1: unknown record type 0");
    r[2][0] = (r[2][0] & ~kTypeMask) | 9;
    EXPECT_EQ(error_of({r[0], r[1], r[2]}), "canonical stream, record 3: unknown record type 9");
}

TEST(CanonWireErrors, FileAnnouncedOutOfOrder) {
    auto r = hello_records();
    r[0][1] = 5;  // the first file must be id 0; found when its name (record 2) completes it
    EXPECT_EQ(error_of({r[0], r[1]}),
              "canonical stream, record 2: file id 5 announced out of order (expected 0)");
}

TEST(CanonWireErrors, UnknownCommandIndex) {
    auto r = hello_records();
    r[2][0] = (r[2][0] & ~kIndexMask) | (std::uint64_t{999} << 8);
    EXPECT_EQ(error_of(r), "canonical stream, record 4: unknown command index 999");
}

TEST(CanonWireErrors, TextLongerThanItsRecords) {
    auto r = hello_records();
    // Word 3, the first payload word, holds the text's length: 1000 bytes claimed, one text
    // record of 19 words (152 bytes) sent.
    ASSERT_EQ(r[2][3], 5u);
    r[2][3] = 1000;
    EXPECT_EQ(error_of(r),
              "canonical stream, record 4: command 'message' has a text of 1000 bytes, only 152 "
              "sent");
}

}  // namespace
}  // namespace interp
