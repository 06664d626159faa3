// The wire form of the canonical stream: every command survives encode -> decode with the same
// text (to_text) and the same source location; texts longer than a record are split and
// joined; malformed sequences are refused with a message.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "interp/canon.hpp"
#include "interp/canon_wire.hpp"

namespace {

using interp::Canon;
using interp::CanonCommand;
using interp::SourceLoc;
namespace canon = interp::canon;
namespace wire = interp::wire;

// Values with fractions beyond the text form's four decimals, negative numbers and set flags,
// so a field dropped, swapped or rounded on the wire changes the text or the exact value.
std::vector<CanonCommand> samples() {
    canon::MoveFlags flags;
    flags.force_full_override = true;
    flags.rotary_degrees = true;
    flags.exact_stop = true;
    const interp::AxisVec end{1.25, -2.5, 3.0625, 45, -90, 180.5};
    canon::Arc arc;
    arc.plane = interp::Plane::ZX;
    arc.end_mm = end;
    arc.centre_mm = {0.5, -0.75, 12};
    arc.turns = -3;
    arc.flags = flags;
    canon::Offsets offsets;
    offsets.wcs = 4;
    offsets.wcs_mm = {10, 20, -30, 1, 2, 3};
    offsets.shift_mm = {-1, -2, -3, 0.5, 0.25, 0.125};
    canon::ConditionalMove cmove;
    cmove.axes[0] = canon::ConditionalMove::AxisWatch{0, -12.5, 7, true, 30.0};
    cmove.axes[2] = canon::ConditionalMove::AxisWatch{2, 3.5, 63, false, std::nullopt};
    cmove.flags.rotary_shortest_path = true;
    return {
        canon::Traverse{end, {}},
        canon::FeedLine{end, flags},
        arc,
        canon::SetFeedRate{20.123456},
        canon::SetRapidRate{0},
        canon::SetFeedMode{false},
        canon::Dwell{1.5},
        canon::SetSpindleSpeed{12000},
        canon::Spindle{interp::SpindleDir::Ccw},
        canon::SpindleOrient{-37.5},
        canon::Coolant{true},
        canon::SpindleClamp{true},
        canon::ToolChange{17},
        canon::SetToolNumber{-1},
        canon::ToolOffset{{0.1, -0.2, 55.5}},
        offsets,
        canon::SelectPlane{interp::Plane::YZ},
        canon::Units{true},
        canon::SetOutput{12, true, true},
        canon::WaitInput{5, true, 2.5},
        canon::Sync{},
        cmove,
        canon::LatchConfig{1, 9, true},
        canon::LatchClear{},
        canon::LatchStopDistance{2},
        canon::Message{"short message"},
        canon::IntMessage{-1234567890123LL},
        canon::HomeDone{2, -7.25},
        canon::Stop{true},
        canon::Warning{"M10 in the 6th edition is a spindle clamp"},
        canon::ProgramEnd{true},
        canon::SetBlending{false, 0.0375},
        canon::SetBlending{true, 0},
    };
}

std::vector<Canon> round_trip(const std::vector<Canon>& in) {
    wire::Encoder enc;
    std::vector<wire::Record> records;
    for (const Canon& c : in) enc.command(c, records);
    enc.end("", records);
    wire::Decoder dec;
    std::vector<Canon> out;
    for (const wire::Record& r : records) {
        switch (dec.feed(r)) {
            case wire::Decoder::Item::Command: {
                Canon c = dec.command();
                out.push_back(c);
                break;
            }
            case wire::Decoder::Item::End:
                EXPECT_FALSE(dec.failed());
                return out;
            case wire::Decoder::Item::None:
                break;
        }
    }
    ADD_FAILURE() << "no end record";
    return out;
}

void expect_same(const Canon& a, const Canon& b) {
    EXPECT_EQ(interp::to_text(a), interp::to_text(b));
    EXPECT_EQ(a.cmd.index(), b.cmd.index());
    EXPECT_EQ(a.loc.file, b.loc.file);
    EXPECT_EQ(a.loc.line, b.loc.line);
    EXPECT_EQ(a.loc.col, b.loc.col);
}

TEST(CanonWire, EverySampleRoundTripsWithItsTextAndLocation) {
    std::vector<Canon> in;
    int line = 1;
    for (CanonCommand& c : samples())
        in.push_back(Canon{SourceLoc{"part.ngc", line++, 3 + line % 5}, c});
    const std::vector<Canon> out = round_trip(in);
    ASSERT_EQ(out.size(), in.size());
    for (std::size_t i = 0; i < in.size(); ++i) {
        SCOPED_TRACE(interp::to_text(in[i]));
        expect_same(in[i], out[i]);
    }
}

TEST(CanonWire, NumbersSurviveExactlyNotJustToFourDecimals) {
    canon::FeedLine f;
    f.end_mm = {0.1, 1.0 / 3.0, -1e-12, 123456.789012345, 0, -0.0};
    const std::vector<Canon> out = round_trip({Canon{SourceLoc{"a.ngc", 1, 1}, f}});
    ASSERT_EQ(out.size(), 1u);
    const auto& g = std::get<canon::FeedLine>(out[0].cmd);
    for (std::size_t k = 0; k < f.end_mm.size(); ++k) EXPECT_EQ(g.end_mm[k], f.end_mm[k]) << k;
    EXPECT_TRUE(std::signbit(g.end_mm[5]));
}

// Every alternative of the variant, default-constructed, including commands added after this
// test was written: each needs a field list in canon_wire.cpp.
template <std::size_t... I>
void every_alternative(std::index_sequence<I...>) {
    (
        [] {
            const CanonCommand c{std::in_place_index<I>};
            SCOPED_TRACE(interp::to_text(c));
            EXPECT_TRUE(wire::has_wire_form(c)) << "command index " << I;
            if (!wire::has_wire_form(c)) return;
            const Canon in{SourceLoc{"x.ngc", 2, 1}, c};
            const std::vector<Canon> out = round_trip({in});
            ASSERT_EQ(out.size(), 1u);
            expect_same(in, out[0]);
        }(),
        ...);
}

TEST(CanonWire, EveryAlternativeOfTheVariantHasAWireForm) {
    every_alternative(std::make_index_sequence<std::variant_size_v<CanonCommand>>{});
}

TEST(CanonWire, LongTextsAreSplitOverContinuationRecordsAndJoined) {
    std::string text;
    for (int i = 0; i < 100; ++i) text += "message part " + std::to_string(i) + "; ";
    text += "\xe4\xb8\xad\xe6\x96\x87";  // UTF-8 passes through as bytes
    wire::Encoder enc;
    std::vector<wire::Record> records;
    enc.command(Canon{SourceLoc{"m.ngc", 9, 1}, canon::Message{text}}, records);
    // One file record (+1 continuation for the name), the command, and the text's records.
    const std::size_t per_record = (wire::kWireFields - 1) * 8;
    EXPECT_EQ(records.size(), 2 + 1 + (text.size() + per_record - 1) / per_record);
    const std::vector<Canon> out =
        round_trip({Canon{SourceLoc{"m.ngc", 9, 1}, canon::Message{text}},
                    Canon{SourceLoc{"m.ngc", 10, 1}, canon::Sync{}}});
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(std::get<canon::Message>(out[0].cmd).text, text);
    EXPECT_EQ(out[1].loc.line, 10);
}

TEST(CanonWire, FilesAreAnnouncedOnceAndKeptApart) {
    wire::Encoder enc;
    std::vector<wire::Record> records;
    enc.command(Canon{SourceLoc{"main.ngc", 1, 1}, canon::Sync{}}, records);
    const std::size_t after_first = records.size();
    enc.command(Canon{SourceLoc{"main.ngc", 2, 1}, canon::Sync{}}, records);
    EXPECT_EQ(records.size(), after_first + 1) << "a known file is not announced again";
    const std::vector<Canon> out =
        round_trip({Canon{SourceLoc{"main.ngc", 1, 1}, canon::Sync{}},
                    Canon{SourceLoc{"public.dat", 40, 2}, canon::Dwell{1}},
                    Canon{SourceLoc{"main.ngc", 3, 5}, canon::Sync{}}});
    ASSERT_EQ(out.size(), 3u);
    EXPECT_EQ(out[0].loc.file, "main.ngc");
    EXPECT_EQ(out[1].loc.file, "public.dat");
    EXPECT_EQ(out[2].loc.file, "main.ngc");
    EXPECT_EQ(out[2].loc.col, 5);
}

TEST(CanonWire, EndRecordCarriesTheErrorText) {
    wire::Encoder enc;
    std::vector<wire::Record> records;
    const std::string error = "part.ngc:3:8: expected a number or '=' after Q";
    enc.end(error, records);
    wire::Decoder dec;
    wire::Decoder::Item item = wire::Decoder::Item::None;
    for (const auto& r : records) item = dec.feed(r);
    EXPECT_EQ(item, wire::Decoder::Item::End);
    EXPECT_TRUE(dec.failed());
    EXPECT_EQ(dec.error(), error);
    EXPECT_FALSE(dec.error_loc());  // a text only: no place apart from it
    EXPECT_EQ(dec.error_cause(), error);
}

TEST(CanonWire, EndRecordCarriesThePlaceApartFromTheCause) {
    wire::Encoder enc;
    std::vector<wire::Record> records;
    enc.end(SourceLoc{"part.ngc", 3, 8}, "expected a number or '=' after Q", records);
    ASSERT_EQ(records.size(), 4u);  // file, its name, end, its text
    wire::Decoder dec;
    wire::Decoder::Item item = wire::Decoder::Item::None;
    for (const auto& r : records) item = dec.feed(r);
    EXPECT_EQ(item, wire::Decoder::Item::End);
    EXPECT_TRUE(dec.failed());
    EXPECT_EQ(dec.error(), "part.ngc:3:8: expected a number or '=' after Q");
    ASSERT_TRUE(dec.error_loc());
    EXPECT_EQ(dec.error_loc()->file, "part.ngc");
    EXPECT_EQ(dec.error_loc()->line, 3);
    EXPECT_EQ(dec.error_loc()->col, 8);
    EXPECT_EQ(dec.error_cause(), "expected a number or '=' after Q");
    wire::Decoder unannounced;  // the end record without the file record before it
    EXPECT_THROW(unannounced.feed(records[2]), wire::Error);
}

// A producer that drops a command it has no room for (motion.messages nobody reads) forgets the
// files announced only with it; the next command naming such a file announces it again.
TEST(CanonWire, AFileAnnouncedOnlyInDroppedRecordsIsAnnouncedAgain) {
    wire::Encoder enc;
    std::vector<wire::Record> delivered, dropped;
    enc.command(Canon{SourceLoc{"main.ngc", 1, 1}, canon::Message{"one"}}, delivered);
    const std::size_t files = enc.files_announced();
    EXPECT_EQ(files, 1u);
    enc.command(Canon{SourceLoc{"sub.ngc", 2, 1}, canon::Message{"two"}}, dropped);
    enc.forget_files_after(files);
    enc.command(Canon{SourceLoc{"sub.ngc", 3, 1}, canon::Message{"three"}}, delivered);
    wire::Decoder dec;
    std::vector<Canon> out;
    for (const auto& r : delivered)
        if (dec.feed(r) == wire::Decoder::Item::Command) out.push_back(dec.command());
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[1].loc.file, "sub.ngc");
    EXPECT_EQ(out[1].loc.line, 3);
    ASSERT_TRUE(std::holds_alternative<canon::Message>(out[1].cmd));
    EXPECT_EQ(std::get<canon::Message>(out[1].cmd).text, "three");
}

TEST(CanonWire, MalformedSequencesAreRefused) {
    wire::Encoder enc;
    std::vector<wire::Record> records;
    enc.command(Canon{SourceLoc{"f.ngc", 1, 1}, canon::Message{"hello"}}, records);
    ASSERT_EQ(records.size(), 4u);  // file, its name, command, its text
    {
        wire::Decoder dec;  // the command without its file announcement
        EXPECT_THROW(dec.feed(records[2]), wire::Error);
    }
    {
        wire::Decoder dec;  // a command record where a text continuation must come
        dec.feed(records[0]);
        dec.feed(records[1]);
        dec.feed(records[2]);
        EXPECT_THROW(dec.feed(records[2]), wire::Error);
    }
    {
        wire::Decoder dec;  // a continuation with nothing before it
        EXPECT_THROW(dec.feed(records[1]), wire::Error);
    }
    {
        wire::Decoder dec;  // an index past the variant
        dec.feed(records[0]);
        dec.feed(records[1]);
        wire::Record bad = records[2];
        bad[0] = (bad[0] & ~(std::uint64_t{0xffff} << 8)) | (std::uint64_t{999} << 8);
        bad[0] &= ~(std::uint64_t{0xffffffff} << 24);
        EXPECT_THROW(dec.feed(bad), wire::Error);
    }
}

}  // namespace
