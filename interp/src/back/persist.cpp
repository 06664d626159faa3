// Persistent settings file: parse, format, atomic save (see persist.hpp for the format).
#include "interp/persist.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "interp/block.hpp"
#include "text_lines.hpp"

namespace interp {

namespace {

struct Token {
    std::string text;
    int col;
};

std::vector<Token> split(const std::string& line) {
    std::vector<Token> out;
    std::size_t i = 0;
    while (i < line.size()) {
        if (std::isspace(static_cast<unsigned char>(line[i]))) {
            ++i;
            continue;
        }
        std::size_t j = i;
        while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
        out.push_back({line.substr(i, j - i), static_cast<int>(i) + 1});
        i = j;
    }
    return out;
}

class LineParser {
  public:
    LineParser(std::string_view name, int line, std::vector<Token> toks)
        : name_(name), line_(line), toks_(std::move(toks)) {}

    [[noreturn]] void fail(int col, const std::string& why) const {
        throw Error(SourceLoc{name_, line_, col}, why);
    }
    void expect_count(std::size_t n) const {
        if (toks_.size() != n)
            fail(toks_.front().col, fmt::format("settings: '{}' needs {} values, found {}",
                                                toks_.front().text, n - 1, toks_.size() - 1));
    }
    double num(std::size_t i) const {
        const std::string& t = toks_[i].text;
        double v = 0;
        auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (ec != std::errc() || p != t.data() + t.size())
            fail(toks_[i].col, fmt::format("settings: '{}' is not a number", t));
        return v;
    }
    int integer(std::size_t i, int lo, int hi) const {
        double v = num(i);
        if (v != static_cast<int>(v) || v < lo || v > hi)
            fail(toks_[i].col,
                 fmt::format("settings: '{}' must be an integer in {}..{}", toks_[i].text, lo, hi));
        return static_cast<int>(v);
    }
    AxisVec axes(std::size_t first) const {
        AxisVec v{};
        for (int a = 0; a < kMachineAxes; ++a) v[a] = num(first + a);
        return v;
    }
    const std::vector<Token>& toks() const { return toks_; }

  private:
    std::string_view name_;
    int line_;
    std::vector<Token> toks_;
};

void parse_entry(const LineParser& p, Settings& s) {
    const std::string& key = p.toks().front().text;
    if (key == "wcs") {
        p.expect_count(2 + kMachineAxes);
        s.offsets.wcs[p.integer(1, 1, kWorkSystems) - 1] = p.axes(2);
    } else if (key == "common") {
        p.expect_count(1 + kMachineAxes);
        s.offsets.common = p.axes(1);
    } else if (key == "g92") {
        p.expect_count(1 + kMachineAxes);
        s.offsets.g92 = p.axes(1);
    } else if (key == "tool") {
        p.expect_count(6);
        ToolEntry& e = s.tools.at(p.integer(1, 0, 1000000));
        e.offset_mm = {p.num(2), p.num(3), p.num(4)};
        e.diameter_mm = p.num(5);
        if (e.diameter_mm < 0) p.fail(p.toks()[5].col, "settings: negative tool diameter");
    } else if (key == "param") {
        p.expect_count(3);
        s.params[p.toks()[1].text] = p.num(2);
    } else {
        p.fail(p.toks().front().col, fmt::format("settings: unknown entry '{}'", key));
    }
}

std::string axes_line(const AxisVec& v) {
    std::string s;
    for (double d : v) s += fmt::format(" {}", d);  // shortest round-trip form
    return s;
}

// `err` is the failed call's errno, taken before any clean-up call could change it.
[[noreturn]] void sys_fail(const std::string& what, const std::string& path, int err) {
    throw std::runtime_error(fmt::format("{}: {}: {}", path, what, std::strerror(err)));
}

// A failed save removes its temporary file, so the old settings file is all that is left.
[[noreturn]] void abandon_tmp(int fd, const std::string& tmp, const char* verb, const char* what) {
    const int err = errno;
    if (fd >= 0) ::close(fd);
    ::unlink(tmp.c_str());
    sys_fail(fmt::format("cannot {} {}", verb, what), tmp, err);
}

}  // namespace

Settings parse_settings(const std::string& text, const std::string& name) {
    Settings s;
    std::istringstream in(text);
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
        ++line_no;
        if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
        auto toks = split(line);
        if (toks.empty()) continue;
        parse_entry(LineParser(name, line_no, std::move(toks)), s);
    }
    return s;
}

Settings load_settings(const std::string& path) {
    // A directory opens like a file and reads as empty: it would load as the defaults, and the
    // next save would fail far from the cause.
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw Error(SourceLoc{path, 0, 0},
                    fmt::format("settings: cannot read file: {}", std::strerror(EISDIR)));
    std::ifstream f(path, std::ios::binary);
    if (!f) {
        const int err = errno;
        if (!std::filesystem::exists(path)) return Settings{};
        throw Error(SourceLoc{path, 0, 0},
                    fmt::format("settings: cannot read file: {}", std::strerror(err)));
    }
    std::ostringstream ss;
    ss << f.rdbuf();
    if (f.bad()) throw Error(SourceLoc{path, 0, 0}, "settings: cannot read file: read error");
    return parse_settings(ss.str(), path);
}

namespace {

// Every entry of `s` as the file writes it, by its key ("wcs 3", "common", "g92", "tool 7",
// "param NAME"), in the file's order.
std::vector<std::pair<std::string, std::string>> entry_lines(const Settings& s) {
    std::vector<std::pair<std::string, std::string>> out;
    for (int i = 0; i < kWorkSystems; ++i)
        out.emplace_back(fmt::format("wcs {}", i + 1),
                         fmt::format("wcs {}{}", i + 1, axes_line(s.offsets.wcs[i])));
    out.emplace_back("common", "common" + axes_line(s.offsets.common));
    out.emplace_back("g92", "g92" + axes_line(s.offsets.g92));
    for (const auto& [n, e] : s.tools.entries())
        out.emplace_back(fmt::format("tool {}", n),
                         fmt::format("tool {} {} {} {} {}", n, e.offset_mm[0], e.offset_mm[1],
                                     e.offset_mm[2], e.diameter_mm));
    for (const auto& [k, v] : s.params)
        out.emplace_back("param " + k, fmt::format("param {} {}", k, v));
    return out;
}

// The key of a line parse_settings has accepted (as entry_lines names it).
std::string key_of(const std::vector<Token>& toks) {
    const std::string& kind = toks.front().text;
    if (kind == "wcs" || kind == "tool") {
        double n = 0;
        std::from_chars(toks[1].text.data(), toks[1].text.data() + toks[1].text.size(), n);
        return fmt::format("{} {}", kind, static_cast<int>(n));
    }
    if (kind == "param") return "param " + toks[1].text;
    return kind;
}

}  // namespace

std::string format_settings(const Settings& s) {
    std::string out = "# cnc interpreter persistent settings (mm)\n";
    for (const auto& [key, line] : entry_lines(s)) out += line + "\n";
    return out;
}

std::string update_settings_text(const std::string& old_text, const Settings& s,
                                 const std::string& name) {
    if (old_text.empty()) return format_settings(s);
    std::map<std::string, std::string> was;
    for (auto& [key, line] : entry_lines(parse_settings(old_text, name))) was[key] = line;
    const auto now_lines = entry_lines(s);
    const std::map<std::string, std::string> now(now_lines.begin(), now_lines.end());
    std::string out;
    std::set<std::string> listed;
    text_lines::for_each(old_text, [&](std::string line, const std::string& ending) {
        const auto toks = split(line.substr(0, line.find('#')));
        if (!toks.empty()) {
            const std::string key = key_of(toks);
            listed.insert(key);
            // A line for an entry `s` lacks (the tools, while a tool table holds them) stays.
            if (auto it = now.find(key); it != now.end() && was.at(key) != it->second) {
                const std::size_t begin = static_cast<std::size_t>(toks.front().col) - 1;
                const std::size_t end =
                    static_cast<std::size_t>(toks.back().col) - 1 + toks.back().text.size();
                line.replace(begin, end - begin, it->second);
            }
        }
        out += line + ending;
    });
    const std::string ending = text_lines::ending_of(old_text);
    for (const auto& [key, line] : now_lines) {
        auto it = was.find(key);
        if (!listed.count(key) && (it == was.end() || it->second != line))
            text_lines::append_line(out, line, ending);
    }
    return out;
}

namespace {

// Temporary file in the same folder, fsync, rename over `path`, fsync the folder: a crash
// leaves the old file or the new one, never a torn one. `what` names the contents in errors.
void write_file_atomic(const std::string& path, const std::string& text, const char* what) {
    const std::string tmp = path + ".tmp";
    int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) sys_fail(fmt::format("cannot create temporary {} file", what), tmp, errno);
    std::size_t done = 0;
    while (done < text.size()) {
        ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            abandon_tmp(fd, tmp, "write", what);
        }
        done += static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0) abandon_tmp(fd, tmp, "fsync", what);
    if (::close(fd) != 0) abandon_tmp(-1, tmp, "write", what);
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        sys_fail(fmt::format("cannot replace {} file", what), path, err);
    }
    // The rename itself must reach the disk, or a crash could bring back the old name.
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    const std::filesystem::path dir = parent.empty() ? std::filesystem::path(".") : parent;
    int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
}

// The file a save edits: `path` once it exists, else `seed`, else none (empty). A directory in
// the way of `path` gives none too, so that the save fails where it writes, naming it.
struct SavedText {
    std::string file;
    std::string text;
};

SavedText saved_text(const std::string& path, const std::string& seed, const char* what) {
    std::error_code ec;
    std::string from = path;
    if (!std::filesystem::exists(path, ec)) {
        if (seed.empty() || !std::filesystem::exists(seed, ec)) return {};
        from = seed;
    }
    if (std::filesystem::is_directory(from, ec)) return {};
    std::ifstream f(from, std::ios::binary);
    if (!f) sys_fail(fmt::format("cannot read {} file", what), from, errno);
    std::ostringstream ss;
    ss << f.rdbuf();
    if (f.bad()) sys_fail(fmt::format("cannot read {} file", what), from, EIO);
    return {from, ss.str()};
}

}  // namespace

void save_settings_atomic(const std::string& path, const Settings& s, const std::string& seed) {
    const SavedText base = saved_text(path, seed, "settings");
    write_file_atomic(path, update_settings_text(base.text, s, base.file), "settings");
}

void save_tool_table_atomic(const std::string& path, const ToolTable& t, const std::string& seed) {
    const SavedText base = saved_text(path, seed, "tool table");
    write_file_atomic(path, update_linuxcnc_tool_table(base.text, t, base.file), "tool table");
}

namespace {

// FNV-1a: a hash every build computes alike, so that two builds name the same lock file.
std::uint64_t fnv1a(std::string_view s) {
    std::uint64_t h = 1469598103934665603ULL;
    for (char c : s) {
        h ^= static_cast<unsigned char>(c);
        h *= 1099511628211ULL;
    }
    return h;
}

// The process id the holder wrote into its lock file; 0 when none is there yet.
long holder_of(int fd) {
    char buf[32] = {};
    if (::pread(fd, buf, sizeof buf - 1, 0) <= 0) return 0;
    return std::strtol(buf, nullptr, 10);
}

bool same_file(int fd, const std::string& path) {
    struct stat held {};
    struct stat named {};
    return ::fstat(fd, &held) == 0 && ::stat(path.c_str(), &named) == 0 &&
           held.st_dev == named.st_dev && held.st_ino == named.st_ino;
}

int lock_now(int fd) {
    int r = 0;
    while ((r = ::flock(fd, LOCK_EX | LOCK_NB)) != 0 && errno == EINTR) {
    }
    return r == 0 ? 0 : errno;
}

}  // namespace

std::string SettingsFileLock::lock_file_of(const std::string& path, const std::string& lock_dir) {
    std::error_code ec;
    std::filesystem::path real = std::filesystem::weakly_canonical(path, ec);
    if (ec) real = std::filesystem::absolute(path, ec).lexically_normal();
    return (std::filesystem::path(lock_dir) /
            fmt::format("{}-{:016x}.lock", real.filename().string(), fnv1a(real.string())))
        .string();
}

SettingsFileLock::SettingsFileLock(const std::string& path, const std::string& lock_dir)
    : lock_file_(lock_file_of(path, lock_dir)) {
    auto fail = [&](int err) {
        throw std::runtime_error(fmt::format("{}: cannot lock settings file: {}: {}", path,
                                             lock_file_, std::strerror(err)));
    };
    // Open to every user like /tmp (the umask would narrow mkdir's mode): runs of other users on
    // the same settings files must find the same locks.
    if (::mkdir(lock_dir.c_str(), 01777) == 0)
        ::chmod(lock_dir.c_str(), 01777);
    else if (errno != EEXIST)
        fail(errno);
    // A holder removes its lock file as it lets go; a lock taken on the file it removed would
    // keep nobody out, so such a lock is dropped and taken again on the new file.
    for (int attempt = 0; attempt < 100; ++attempt) {
        int fd = ::open(lock_file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
        if (fd < 0 && errno == EACCES)  // another user's lock file: flock needs no write access
            fd = ::open(lock_file_.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) fail(errno);
        if (const int err = lock_now(fd); err != 0) {
            const long pid = err == EWOULDBLOCK ? holder_of(fd) : 0;
            ::close(fd);
            if (err != EWOULDBLOCK) fail(err);
            throw std::runtime_error(fmt::format(
                "{}: settings file in use by another run ({}); two runs on the same settings "
                "would overwrite each other's changes",
                path, pid > 0 ? fmt::format("pid {}", pid) : std::string("holder unknown")));
        }
        if (!same_file(fd, lock_file_)) {
            ::close(fd);
            continue;
        }
        fd_ = fd;
        // Only the refusal message of another run reads this: a failed write changes nothing.
        const std::string pid = fmt::format("{}\n", ::getpid());
        [[maybe_unused]] const bool written =
            ::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, pid.data(), pid.size(), 0) > 0;
        return;
    }
    fail(EAGAIN);
}

SettingsFileLock::~SettingsFileLock() {
    if (fd_ < 0) return;
    // Removed while still locked, so no one can lock this file after we let go (see above).
    ::unlink(lock_file_.c_str());
    ::close(fd_);
}

}  // namespace interp
