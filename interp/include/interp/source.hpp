#pragma once
// Program text, streamed line by line. A file is read through a fixed 64 KiB window so a
// million-line program never sits whole in memory; subprogram labels (O1234, O"name") are found
// once by a fast scan at open and kept as byte offsets, so a call is a seek, not a search.
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "interp/block.hpp"

namespace interp {

// A position in a source: byte offset of a line start and that line's number (1-based).
struct SourcePos {
    std::uint64_t offset = 0;
    int line = 1;
    friend bool operator==(const SourcePos&, const SourcePos&) = default;
};

// A sequence number written twice in one program (main program or one subprogram). Allowed
// (LEX-07), but M99 P / a search then finds the first one, which is rarely what was meant.
struct DuplicateSequence {
    std::int64_t n = 0;
    int line = 0;
    int col = 0;
};

// Where a subprogram label was defined: the label line itself.
struct LabelSite {
    SourcePos pos;
    int col = 1;
};

class Source {
  public:
    // Opens a file for streaming. Throws Error naming the file when it cannot be read.
    static std::unique_ptr<Source> open_file(const std::string& path);
    // Wraps program text held in memory (MDI, tests); `name` is used in diagnostics.
    static std::unique_ptr<Source> from_string(std::string name, std::string text);

    ~Source();
    Source(const Source&) = delete;
    Source& operator=(const Source&) = delete;

    // The file name as used in SourceLoc; stable for the lifetime of this Source.
    std::string_view name() const { return name_; }

    // Reads the next line (without its line terminator; a trailing '\r' is dropped). The view
    // stays valid until the next call to next_line() or seek(). Returns false at end of input.
    bool next_line(std::string_view& line);
    // Number and start of the line most recently returned by next_line().
    int line_number() const { return cur_line_; }
    SourcePos line_start() const { return SourcePos{cur_line_offset_, cur_line_}; }
    // Position of the line that next_line() will return next.
    SourcePos tell() const { return SourcePos{next_offset_, cur_line_ + 1}; }
    void seek(const SourcePos& pos);

    // Subprogram labels found at open. Lookups are case-insensitive for names.
    std::optional<LabelSite> find_label(std::int64_t number) const;
    std::optional<LabelSite> find_label(std::string_view name) const;
    std::size_t label_count() const { return numbered_.size() + named_.size(); }
    // Duplicate sequence numbers found by the same scan (the first kMaxDuplicates), over the
    // whole range the parser accepts for N (to_integer: up to 9e15).
    static constexpr std::size_t kMaxDuplicates = 100;
    static constexpr std::int64_t kMaxSequence = 9'000'000'000'000'000;
    static constexpr std::int64_t kBitmapSequences = std::int64_t{1} << 22;
    const std::vector<DuplicateSequence>& duplicate_sequences() const { return duplicates_; }

  private:
    Source(std::string name, std::FILE* file, std::string text);
    void index_labels();
    void index_line(std::string_view line, SourcePos pos);
    void index_sequence(std::string_view line, std::size_t at, int line_number);
    void begin_sequence_scope();
    bool fill();
    // Discards the rest of a line longer than the limit, then throws Error naming it; reading
    // continues with the next line.
    [[noreturn]] void skip_overlong_line();

    std::string name_;
    std::FILE* file_ = nullptr;        // null for in-memory text
    std::string text_;                 // in-memory text, or the read window of a file
    std::uint64_t window_offset_ = 0;  // file offset of text_[0] (always 0 for in-memory text)
    std::size_t window_pos_ = 0;       // next unread byte in text_
    bool eof_ = false;
    std::string long_line_;  // a line that straddles the window boundary is assembled here
    std::uint64_t next_offset_ = 0;
    std::uint64_t cur_line_offset_ = 0;
    int cur_line_ = 0;
    std::map<std::int64_t, LabelSite> numbered_;
    std::map<std::string, LabelSite, std::less<>> named_;  // upper-cased names
    // Sequence numbers of the current program scope during the scan: a bitmap (grown to the
    // largest N seen, at most kBitmapSequences bits = 512 KiB) and the words of it that were
    // set, so the next label clears only those; N values past the bitmap go to a hash set.
    std::vector<std::uint64_t> seq_bits_;
    std::vector<std::uint32_t> seq_touched_;
    std::unordered_set<std::int64_t> seq_large_;
    std::vector<DuplicateSequence> duplicates_;
};

}  // namespace interp
