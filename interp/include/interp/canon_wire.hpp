#pragma once
// A fixed-size binary form of the canonical stream, for carrying it through a HAL stream (the
// `interp` component writes it, the motion component reads it). Every record is kWireFields
// 64-bit words; a command is one record, plus continuation records for its texts (M801
// messages, warnings); a file name is announced once in a file record before the first command
// that names it; the producer's last word is an end record (with an error text if it failed).
//
//   word 0   type (bits 0-7) | command index (bits 8-23) | continuation records (bits 24-55)
//   command  word 1 = line | col << 32, word 2 = file id, words 3.. = the command's fields
//   file     word 1 = file id, name in continuations
//   end      word 1 = 1 if failed; words 2 and 3 = where it failed, if the producer knows:
//            word 2 = line | col << 32, word 3 = file id + 1 (0: no place, words 2 and 3
//            unused); the error in continuations (the cause alone when a place is given)
//   continuation  words 1.. = text bytes
//
// The fields of each command are listed once, in canon_wire.cpp (`fields(archive, command)`),
// and the same list encodes and decodes: adding a canonical command means adding one such
// function. Encoder and decoder must come from the same build (the command index is the
// position in the CanonCommand variant). Configuration world only (allocates, throws).
#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "interp/canon.hpp"

namespace interp::wire {

inline constexpr std::size_t kWireFields = 20;
using Record = std::array<std::uint64_t, kWireFields>;
// The layout of a HAL stream carrying records: one u64 field (cfg letter k) per word.
inline constexpr char kStreamLayout[] = "kkkkkkkkkkkkkkkkkkkk";
static_assert(sizeof(kStreamLayout) - 1 == kWireFields);

// A record sequence that does not decode (a bug or a foreign producer): what and where.
class Error : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// True if the command type has a wire form (a `fields` function in canon_wire.cpp).
bool has_wire_form(const CanonCommand& c);

class Encoder {
  public:
    // Appends the records of one command (a file record first if its file is new). Throws
    // wire::Error for a command without a wire form.
    void command(const Canon& c, std::vector<Record>& out);
    // Appends the end record: `error` empty for a program that completed.
    void end(std::string_view error, std::vector<Record>& out);
    // Appends the end record of a program that failed at `where` because of `cause` (a file
    // record first if the file is new).
    void end(const SourceLoc& where, std::string_view cause, std::vector<Record>& out);

    // Files announced so far. A producer that drops records it could not deliver (a full
    // stream) passes the count from before them to forget_files_after(), so that the next
    // command naming a file announced only in the dropped records announces it again.
    std::size_t files_announced() const { return files_.size(); }
    void forget_files_after(std::size_t count);

  private:
    std::uint32_t file_id(std::string_view file, std::vector<Record>& out);
    std::unordered_map<std::string, std::uint32_t> files_;
};

class Decoder {
  public:
    enum class Item { None, Command, End };
    // Takes the next record. Command: command() holds it (its loc.file stays valid while the
    // decoder lives); End: the stream is over, error() says why if it failed; None: more
    // records are needed. Throws wire::Error on a malformed sequence, naming the record by its
    // number in the stream (1 = the first fed to this decoder).
    Item feed(const Record& r);
    const Canon& command() const { return command_; }
    // After End: failed() and the error, whole ("file:line:col: cause" when the producer gave
    // a place), or as its place (its file stays valid while the decoder lives) and its cause.
    bool failed() const { return failed_; }
    const std::string& error() const { return text_; }
    const std::optional<SourceLoc>& error_loc() const { return error_loc_; }
    const std::string& error_cause() const { return cause_; }

  private:
    Item take(const Record& r);
    Item complete();
    std::uint64_t records_ = 0;  // fed so far, for locating a malformed one
    Record first_{};
    std::uint32_t continuations_left_ = 0;
    std::string text_;               // bytes of the continuation records of the current item
    std::deque<std::string> files_;  // by id; a deque keeps the strings in place
    Canon command_;
    bool failed_ = false;
    std::optional<SourceLoc> error_loc_;
    std::string cause_;
};

}  // namespace interp::wire
