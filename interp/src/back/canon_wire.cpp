#include "interp/canon_wire.hpp"

#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <optional>
#include <type_traits>
#include <utility>
#include <variant>

namespace interp::wire {

namespace {

enum class Type : std::uint8_t { Command = 1, Continuation = 2, File = 3, End = 4 };

constexpr std::size_t kFirstPayloadWord = 3;
constexpr std::size_t kTextBytesPerRecord = (kWireFields - 1) * sizeof(std::uint64_t);

// ---------------------------------------------------------------------------------------------
// The fields of every command, in wire order. One function per type serves both directions:
// the archive either writes the listed members or reads them back.

template <class A>
void fields(A& a, canon::MoveFlags& f) {
    a(f.force_full_override, f.force_programmed_feed, f.rotary_shortest_path, f.rotary_degrees,
      f.exact_stop);
}
template <class A>
void fields(A& a, canon::Traverse& c) {
    a(c.end_mm, c.flags);
}
template <class A>
void fields(A& a, canon::FeedLine& c) {
    a(c.end_mm, c.flags);
}
template <class A>
void fields(A& a, canon::Arc& c) {
    a(c.plane, c.end_mm, c.centre_mm, c.turns, c.flags);
}
template <class A>
void fields(A& a, canon::SetFeedRate& c) {
    a(c.feed_mm_s);
}
template <class A>
void fields(A& a, canon::SetRapidRate& c) {
    a(c.rapid_mm_s);
}
template <class A>
void fields(A& a, canon::SetFeedMode& c) {
    a(c.per_minute);
}
template <class A>
void fields(A& a, canon::Dwell& c) {
    a(c.seconds);
}
template <class A>
void fields(A& a, canon::SetSpindleSpeed& c) {
    a(c.rpm);
}
template <class A>
void fields(A& a, canon::Spindle& c) {
    a(c.dir);
}
template <class A>
void fields(A& a, canon::SpindleOrient& c) {
    a(c.tip_angle_deg);
}
template <class A>
void fields(A& a, canon::Coolant& c) {
    a(c.flood);
}
template <class A>
void fields(A& a, canon::SpindleClamp& c) {
    a(c.clamp);
}
template <class A>
void fields(A& a, canon::ToolChange& c) {
    a(c.tool);
}
template <class A>
void fields(A& a, canon::SetToolNumber& c) {
    a(c.tool);
}
template <class A>
void fields(A& a, canon::ToolOffset& c) {
    a(c.offset_mm);
}
template <class A>
void fields(A& a, canon::Offsets& c) {
    a(c.wcs, c.wcs_mm, c.shift_mm);
}
template <class A>
void fields(A& a, canon::SelectPlane& c) {
    a(c.plane);
}
template <class A>
void fields(A& a, canon::Units& c) {
    a(c.inch);
}
template <class A>
void fields(A& a, canon::SetOutput& c) {
    a(c.port, c.plc_address, c.level);
}
template <class A>
void fields(A& a, canon::WaitInput& c) {
    a(c.port, c.level, c.timeout_s);
}
template <class A>
void fields(A&, canon::Sync&) {}
template <class A>
void fields(A& a, canon::ConditionalMove::AxisWatch& w) {
    a(w.axis, w.speed_mm_s, w.port, w.level, w.max_travel_mm);
}
template <class A>
void fields(A& a, canon::ConditionalMove& c) {
    a(c.axes, c.flags);
}
template <class A>
void fields(A& a, canon::LatchConfig& c) {
    a(c.axis, c.port, c.level);
}
template <class A>
void fields(A&, canon::LatchClear&) {}
template <class A>
void fields(A& a, canon::LatchStopDistance& c) {
    a(c.axis);
}
template <class A>
void fields(A& a, canon::Message& c) {
    a(c.text);
}
template <class A>
void fields(A& a, canon::IntMessage& c) {
    a(c.code);
}
template <class A>
void fields(A& a, canon::HomeDone& c) {
    a(c.axis, c.position_mm);
}
template <class A>
void fields(A& a, canon::Stop& c) {
    a(c.optional);
}
template <class A>
void fields(A& a, canon::Warning& c) {
    a(c.text);
}
template <class A>
void fields(A& a, canon::ProgramEnd& c) {
    a(c.rewind);
}
template <class A>
void fields(A& a, canon::SetBlending& c) {
    a(c.exact, c.tolerance_mm);
}

// ---------------------------------------------------------------------------------------------
// Archives. Numbers take a word each (doubles by bit pattern, so values survive exactly);
// booleans share bit words, allocated when the first one comes; texts put their length in a
// word and their bytes in continuation records.

class Archive {
  protected:
    explicit Archive(std::string_view what) : what_(what) {}
    std::size_t next_word() {
        if (word_ >= kWireFields)
            throw Error(
                fmt::format("canonical command '{}' has more fields than a record holds", what_));
        return word_++;
    }
    // Word and bit for the next boolean.
    std::pair<std::size_t, unsigned> next_bit() {
        if (!bits_word_ || bit_ == 64) {
            bits_word_ = next_word();
            bit_ = 0;
        }
        return {*bits_word_, bit_++};
    }
    std::string_view what_;

  private:
    std::size_t word_ = kFirstPayloadWord;
    std::optional<std::size_t> bits_word_;
    unsigned bit_ = 0;
};

// An archive that does nothing, to ask whether a type has a field list.
struct Probe {
    template <class... T>
    void operator()(T&...) {}
};
template <class T>
concept Listed = requires(Probe& p, T& t) {
    fields(p, t);
};

struct Writer : Archive {
    Writer(Record& r, std::string& text, std::string_view what)
        : Archive(what), record_(r), text_(text) {}

    template <class... T>
    void operator()(T&... v) {
        (put(v), ...);
    }

  private:
    void put(bool v) {
        const auto [w, b] = next_bit();
        if (v) record_[w] |= std::uint64_t{1} << b;
    }
    void put(double v) { record_[next_word()] = std::bit_cast<std::uint64_t>(v); }
    template <class T>
    requires std::is_integral_v<T>
    void put(T v) {
        record_[next_word()] = static_cast<std::uint64_t>(static_cast<std::int64_t>(v));
    }
    template <class T>
    requires std::is_enum_v<T>
    void put(T v) { put(static_cast<std::underlying_type_t<T>>(v)); }
    template <class T, std::size_t N>
    void put(std::array<T, N>& a) {
        for (T& x : a) put(x);
    }
    template <class T>
    void put(std::optional<T>& o) {
        put(o.has_value());
        if (o) put(*o);
    }
    void put(std::string& s) {
        put(static_cast<std::uint64_t>(s.size()));
        text_ += s;
    }
    template <class T>
    requires Listed<T>
    void put(T& nested) { fields(*this, nested); }

    Record& record_;
    std::string& text_;
};

struct Reader : Archive {
    Reader(const Record& r, std::string_view text, std::string_view what)
        : Archive(what), record_(r), text_(text) {}

    template <class... T>
    void operator()(T&... v) {
        (get(v), ...);
    }

  private:
    void get(bool& v) {
        const auto [w, b] = next_bit();
        v = (record_[w] >> b) & 1;
    }
    void get(double& v) { v = std::bit_cast<double>(record_[next_word()]); }
    template <class T>
    requires std::is_integral_v<T>
    void get(T& v) { v = static_cast<T>(static_cast<std::int64_t>(record_[next_word()])); }
    template <class T>
    requires std::is_enum_v<T>
    void get(T& v) {
        std::underlying_type_t<T> raw{};
        get(raw);
        v = static_cast<T>(raw);
    }
    template <class T, std::size_t N>
    void get(std::array<T, N>& a) {
        for (T& x : a) get(x);
    }
    template <class T>
    void get(std::optional<T>& o) {
        bool present = false;
        get(present);
        o.reset();
        if (present) get(o.emplace());
    }
    void get(std::string& s) {
        std::uint64_t size = 0;
        get(size);
        if (size > text_.size() - text_at_)
            throw Error(
                fmt::format("a text of {} bytes, only {} sent", size, text_.size() - text_at_));
        s.assign(text_.substr(text_at_, size));
        text_at_ += size;
    }
    template <class T>
    requires Listed<T>
    void get(T& nested) { fields(*this, nested); }

    const Record& record_;
    std::string_view text_;
    std::size_t text_at_ = 0;
};

// ---------------------------------------------------------------------------------------------

std::uint64_t header(Type type, std::size_t index, std::size_t continuations) {
    return static_cast<std::uint64_t>(type) | (static_cast<std::uint64_t>(index) << 8) |
           (static_cast<std::uint64_t>(continuations) << 24);
}
Type type_of(const Record& r) {
    return static_cast<Type>(r[0] & 0xff);
}
std::size_t index_of(const Record& r) {
    return (r[0] >> 8) & 0xffff;
}
std::uint32_t continuations_of(const Record& r) {
    return static_cast<std::uint32_t>((r[0] >> 24) & 0xffffffff);
}

std::uint64_t location_word(const SourceLoc& loc) {
    return static_cast<std::uint32_t>(loc.line) |
           (static_cast<std::uint64_t>(static_cast<std::uint32_t>(loc.col)) << 32);
}
SourceLoc location_of(std::uint64_t word, std::string_view file) {
    return SourceLoc{file, static_cast<int>(word & 0xffffffff), static_cast<int>(word >> 32)};
}

// Appends `first` and the continuation records carrying `text`.
void append_with_text(Record first, std::string_view text, std::vector<Record>& out) {
    const std::size_t count = (text.size() + kTextBytesPerRecord - 1) / kTextBytesPerRecord;
    if (count > 0xffffffff) throw Error("canonical command text too long for the wire");
    first[0] |= static_cast<std::uint64_t>(count) << 24;
    out.push_back(first);
    for (std::size_t k = 0; k < count; ++k) {
        Record r{};
        r[0] = header(Type::Continuation, 0, 0);
        const std::string_view part = text.substr(k * kTextBytesPerRecord, kTextBytesPerRecord);
        std::memcpy(&r[1], part.data(), part.size());
        out.push_back(r);
    }
}

// The command's name for messages: its text form's first word.
std::string name_of(const CanonCommand& c) {
    const std::string t = to_text(c);
    return t.substr(0, t.find(' '));
}

template <std::size_t I>
bool decode_alternative(const Record& r, std::string_view text, CanonCommand& out) {
    using T = std::variant_alternative_t<I, CanonCommand>;
    if constexpr (Listed<T>) {
        T c{};
        Reader reader(r, text, "");
        try {
            fields(reader, c);
        } catch (const Error& e) {
            // Named only on this path: naming every decoded command would cost a format each.
            throw Error(fmt::format("command '{}' has {}", name_of(CanonCommand{T{}}), e.what()));
        }
        out = std::move(c);
        return true;
    } else {
        return false;
    }
}

template <std::size_t... I>
bool decode_command(std::size_t index, const Record& r, std::string_view text, CanonCommand& out,
                    std::index_sequence<I...>) {
    bool done = false;
    static_cast<void>(
        ((I == index ? (done = decode_alternative<I>(r, text, out), true) : false) || ...));
    return done;
}

}  // namespace

bool has_wire_form(const CanonCommand& c) {
    return std::visit([](const auto& v) { return Listed<std::decay_t<decltype(v)>>; }, c);
}

std::uint32_t Encoder::file_id(std::string_view file, std::vector<Record>& out) {
    const auto [it, added] =
        files_.emplace(std::string(file), static_cast<std::uint32_t>(files_.size()));
    if (added) {
        Record r{};
        r[0] = header(Type::File, 0, 0);
        r[1] = it->second;
        append_with_text(r, file, out);
    }
    return it->second;
}

void Encoder::command(const Canon& c, std::vector<Record>& out) {
    if (!has_wire_form(c.cmd))
        throw Error(fmt::format("{}:{}:{}: canonical command '{}' has no wire form", c.loc.file,
                                c.loc.line, c.loc.col, name_of(c.cmd)));
    const std::uint32_t file = file_id(c.loc.file, out);
    Record r{};
    r[0] = header(Type::Command, c.cmd.index(), 0);
    r[1] = location_word(c.loc);
    r[2] = file;
    std::string text;
    const std::string what = name_of(c.cmd);
    std::visit(
        [&](const auto& cmd) {
            using T = std::decay_t<decltype(cmd)>;
            if constexpr (Listed<T>) {
                Writer w(r, text, what);
                // The writer only reads the members; the field lists take non-const
                // references so that one list serves the reader too.
                fields(w, const_cast<T&>(cmd));
            }
        },
        c.cmd);
    append_with_text(r, text, out);
}

void Encoder::end(std::string_view error, std::vector<Record>& out) {
    Record r{};
    r[0] = header(Type::End, 0, 0);
    r[1] = error.empty() ? 0 : 1;
    append_with_text(r, error, out);
}

void Encoder::end(const SourceLoc& where, std::string_view cause, std::vector<Record>& out) {
    const std::uint32_t file = file_id(where.file, out);
    Record r{};
    r[0] = header(Type::End, 0, 0);
    r[1] = 1;
    r[2] = location_word(where);
    r[3] = std::uint64_t{file} + 1;
    append_with_text(r, cause, out);
}

void Encoder::forget_files_after(std::size_t count) {
    std::erase_if(files_, [count](const auto& f) { return f.second >= count; });
}

Decoder::Item Decoder::feed(const Record& r) {
    ++records_;
    try {
        return take(r);
    } catch (const Error& e) {
        throw Error(fmt::format("canonical stream, record {}: {}", records_, e.what()));
    }
}

Decoder::Item Decoder::take(const Record& r) {
    if (continuations_left_ > 0) {
        if (type_of(r) != Type::Continuation)
            throw Error(fmt::format("expected {} more text record(s), got a record of type {}",
                                    continuations_left_, static_cast<int>(type_of(r))));
        const char* bytes = reinterpret_cast<const char*>(&r[1]);
        text_.append(bytes, kTextBytesPerRecord);
        if (--continuations_left_ > 0) return Item::None;
        return complete();
    }
    const Type t = type_of(r);
    if (t == Type::Continuation) throw Error("a text record with no command or file before it");
    if (t != Type::Command && t != Type::File && t != Type::End)
        throw Error(fmt::format("unknown record type {}", static_cast<int>(t)));
    if (t == Type::Command && r[2] >= files_.size())
        throw Error(fmt::format("command names file id {}, never announced", r[2]));
    if (t == Type::End && r[3] > files_.size())
        throw Error(fmt::format("end record names file id {}, never announced", r[3] - 1));
    first_ = r;
    text_.clear();
    continuations_left_ = continuations_of(r);
    if (continuations_left_ > 0) return Item::None;
    return complete();
}

Decoder::Item Decoder::complete() {
    switch (type_of(first_)) {
        case Type::File: {
            // Texts are padded to whole records; the name ends at the first NUL.
            const std::string name = text_.substr(0, text_.find('\0'));
            if (first_[1] != files_.size())
                throw Error(fmt::format("file id {} announced out of order (expected {})",
                                        first_[1], files_.size()));
            files_.push_back(name);
            return Item::None;
        }
        case Type::End:
            failed_ = first_[1] != 0;
            text_.erase(std::min(text_.find('\0'), text_.size()));
            cause_ = text_;
            error_loc_.reset();
            if (first_[3] != 0) {
                error_loc_ = location_of(first_[2], files_[first_[3] - 1]);
                text_ = fmt::format("{}:{}:{}: {}", error_loc_->file, error_loc_->line,
                                    error_loc_->col, cause_);
            }
            return Item::End;
        default:
            break;
    }
    const std::size_t index = index_of(first_);
    const std::uint64_t file = first_[2];
    command_.loc = location_of(first_[1], files_[file]);
    if (index >= std::variant_size_v<CanonCommand> ||
        !decode_command(index, first_, text_, command_.cmd,
                        std::make_index_sequence<std::variant_size_v<CanonCommand>>{}))
        throw Error(fmt::format("unknown command index {}", index));
    return Item::Command;
}

}  // namespace interp::wire
