#include "interp/source.hpp"

#include <cerrno>
#include <cstring>

#include "interp/text.hpp"

namespace interp {

namespace {
constexpr std::size_t kWindowBytes = 64 * 1024;
// A longer line is certainly not G-code; refusing it keeps memory bounded.
constexpr std::size_t kMaxLineBytes = 1024 * 1024;
}  // namespace

std::unique_ptr<Source> Source::open_file(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (f == nullptr) {
        throw Error(SourceLoc{path, 0, 0},
                    std::string("cannot open program: ") + std::strerror(errno));
    }
    std::unique_ptr<Source> src(new Source(path, f, std::string()));
    src->index_labels();
    return src;
}

std::unique_ptr<Source> Source::from_string(std::string name, std::string text) {
    std::unique_ptr<Source> src(new Source(std::move(name), nullptr, std::move(text)));
    src->index_labels();
    return src;
}

Source::Source(std::string name, std::FILE* file, std::string text)
    : name_(std::move(name)), file_(file), text_(std::move(text)), eof_(file == nullptr) {}

Source::~Source() {
    if (file_ != nullptr) std::fclose(file_);
}

bool Source::fill() {
    // Keep the unread tail, drop what was consumed, append the next window.
    text_.erase(0, window_pos_);
    window_offset_ += window_pos_;
    window_pos_ = 0;
    const std::size_t old = text_.size();
    text_.resize(old + kWindowBytes);
    const std::size_t got = std::fread(text_.data() + old, 1, kWindowBytes, file_);
    text_.resize(old + got);
    if (got == 0) {
        if (std::ferror(file_)) {
            throw Error(SourceLoc{name_, cur_line_, 0}, "read error in program file");
        }
        eof_ = true;
    }
    return got != 0;
}

bool Source::next_line(std::string_view& line) {
    for (;;) {
        const char* start = text_.data() + window_pos_;
        const std::size_t avail = text_.size() - window_pos_;
        const char* nl = static_cast<const char*>(std::memchr(start, '\n', avail));
        if (nl == nullptr && !eof_) {
            if (avail > kMaxLineBytes) skip_overlong_line();
            fill();
            continue;
        }
        if (nl == nullptr && avail == 0) return false;
        const std::size_t len = nl != nullptr ? static_cast<std::size_t>(nl - start) : avail;
        line = std::string_view(start, len);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        cur_line_offset_ = window_offset_ + window_pos_;
        window_pos_ += len + (nl != nullptr ? 1 : 0);
        next_offset_ = window_offset_ + window_pos_;
        ++cur_line_;
        return true;
    }
}

void Source::skip_overlong_line() {
    const int line = cur_line_ + 1;
    for (;;) {
        window_pos_ = text_.size();
        fill();
        if (eof_) break;
        const char* nl = static_cast<const char*>(std::memchr(text_.data(), '\n', text_.size()));
        if (nl != nullptr) {
            window_pos_ = static_cast<std::size_t>(nl - text_.data()) + 1;
            break;
        }
    }
    cur_line_offset_ = next_offset_;
    next_offset_ = window_offset_ + window_pos_;
    cur_line_ = line;
    throw Error(SourceLoc{name_, line, 1}, "line is longer than 1 MiB");
}

void Source::seek(const SourcePos& pos) {
    const bool in_window =
        pos.offset >= window_offset_ && pos.offset <= window_offset_ + text_.size();
    if (in_window) {
        window_pos_ = static_cast<std::size_t>(pos.offset - window_offset_);
    } else {
        if (fseeko(file_, static_cast<off_t>(pos.offset), SEEK_SET) != 0) {
            throw Error(SourceLoc{name_, pos.line, 0}, "cannot seek in program file");
        }
        text_.clear();
        window_offset_ = pos.offset;
        window_pos_ = 0;
        eof_ = false;
    }
    next_offset_ = pos.offset;
    cur_line_ = pos.line - 1;
    cur_line_offset_ = pos.offset;
}

// Records N at `at` in the current program scope; a second N of the same value is a duplicate.
void Source::index_sequence(std::string_view line, std::size_t at, int line_number) {
    std::size_t i = at + 1;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i >= line.size() || !is_digit(line[i])) return;
    std::int64_t n = 0;
    while (i < line.size() && is_digit(line[i])) {
        // Past this the parser rejects the N word anyway ("out of range"); it is no duplicate.
        if (n > kMaxSequence / 10) return;
        n = n * 10 + (line[i] - '0');
        ++i;
    }
    if (n >= kBitmapSequences) {  // rare: a hash set keeps the bitmap small
        if (!seq_large_.insert(n).second && duplicates_.size() < kMaxDuplicates)
            duplicates_.push_back({n, line_number, static_cast<int>(at) + 1});
        return;
    }
    const std::size_t word = static_cast<std::size_t>(n) / 64;
    const std::uint64_t bit = std::uint64_t{1} << (n % 64);
    if (word >= seq_bits_.size()) seq_bits_.resize(word + 1);
    if (seq_bits_[word] & bit) {
        if (duplicates_.size() < kMaxDuplicates)
            duplicates_.push_back({n, line_number, static_cast<int>(at) + 1});
        return;
    }
    if (seq_bits_[word] == 0) seq_touched_.push_back(static_cast<std::uint32_t>(word));
    seq_bits_[word] |= bit;
}

void Source::begin_sequence_scope() {
    for (std::uint32_t w : seq_touched_) seq_bits_[w] = 0;
    seq_touched_.clear();
    if (!seq_large_.empty()) seq_large_.clear();
}

void Source::index_line(std::string_view line, SourcePos pos) {
    std::size_t i = 0;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::size_t n_at = i;  // a block-delete '/' may stand before N
    while (n_at < line.size() && (line[n_at] == ' ' || line[n_at] == '\t' || line[n_at] == '/'))
        ++n_at;
    if (n_at < line.size() && (line[n_at] == 'N' || line[n_at] == 'n')) {
        index_sequence(line, n_at, pos.line);
        return;
    }
    if (i >= line.size() || (line[i] != 'O' && line[i] != 'o')) return;
    begin_sequence_scope();
    const int col = static_cast<int>(i) + 1;
    ++i;
    const LabelSite site{pos, col};
    if (i < line.size() && is_digit(line[i])) {
        std::int64_t number = 0;
        while (i < line.size() && is_digit(line[i]) && number < (std::int64_t{1} << 40)) {
            number = number * 10 + (line[i] - '0');
            ++i;
        }
        auto [it, inserted] = numbered_.emplace(number, site);
        if (!inserted) {
            throw Error(SourceLoc{name_, pos.line, col}, "subprogram O" + std::to_string(number) +
                                                             " is defined twice (first at line " +
                                                             std::to_string(it->second.pos.line) +
                                                             ")");
        }
        return;
    }
    const std::size_t open_len = quote_length(line.substr(i));
    if (open_len == 0) return;
    i += open_len;
    std::size_t end = i;
    while (end < line.size() && quote_length(line.substr(end)) == 0) ++end;
    std::string key = to_upper(line.substr(i, end - i));
    auto [it, inserted] = named_.emplace(key, site);
    if (!inserted) {
        throw Error(SourceLoc{name_, pos.line, col}, "subprogram O\"" +
                                                         std::string(line.substr(i, end - i)) +
                                                         "\" is defined twice (first at line " +
                                                         std::to_string(it->second.pos.line) + ")");
    }
}

void Source::index_labels() {
    std::string_view line;
    for (;;) {
        try {
            if (!next_line(line)) break;
        } catch (const Error&) {
            continue;  // an over-long line: reported again when the program reaches it
        }
        index_line(line, line_start());
    }
    // The scan's bookkeeping is not needed while the program runs.
    seq_bits_ = {};
    seq_touched_ = {};
    seq_large_ = {};
    seek(SourcePos{});
}

std::optional<LabelSite> Source::find_label(std::int64_t number) const {
    auto it = numbered_.find(number);
    if (it == numbered_.end()) return std::nullopt;
    return it->second;
}

std::optional<LabelSite> Source::find_label(std::string_view name) const {
    auto it = named_.find(to_upper(name));
    if (it == named_.end()) return std::nullopt;
    return it->second;
}

}  // namespace interp
