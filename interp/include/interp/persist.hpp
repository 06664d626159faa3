#pragma once
// Settings that survive power cycles: work offsets, the G92 shift, the tool table and the named
// parameters the manual says persist. Stored as a small line-oriented text file:
//
//   # comment
//   wcs <1..6> X Y Z A B C
//   common X Y Z A B C
//   g92 X Y Z A B C
//   tool <n> <offset X> <offset Y> <offset Z> <diameter>
//   param <NAME> <value>
//
// Written atomically (temporary file in the same directory, fsync, rename, fsync directory), so a
// crash leaves either the old or the new file, never a torn one.
#include <map>
#include <string>

#include "interp/offsets.hpp"
#include "interp/tooltable.hpp"

namespace interp {

struct Settings {
    WorkOffsets offsets;
    ToolTable tools;
    std::map<std::string, double, std::less<>> params;
    bool operator==(const Settings&) const = default;
};

// A missing file gives default settings. A malformed one throws interp::Error naming
// "file:line:col: cause", one that cannot be read (or is a directory) "file:0:0: settings:
// cannot read file: cause"; nothing is changed on disk.
Settings load_settings(const std::string& path);
Settings parse_settings(const std::string& text, const std::string& name);
// A new settings file: a header comment, then every entry in the order above.
std::string format_settings(const Settings& s);
// `old_text` (a file parse_settings accepts, `name` in its errors) rewritten to hold `s`, so
// that what a person wrote in it survives: every line stays as it was (comments, blank lines,
// order, spacing, line endings) except an entry whose value `s` changes, whose words are written
// anew in format_settings' form before the line's own comment. Entries the file lacks are
// appended in format_settings' order (offsets only when not at their default); a line for an
// entry `s` lacks (a tool, while a tool table holds the tools) stays. An empty `old_text` gives
// format_settings(s). Throws interp::Error "name:line:col: cause" for a bad line.
std::string update_settings_text(const std::string& old_text, const Settings& s,
                                 const std::string& name);
// Writes `s` into `path` as update_settings_text of the file there now or, while there is none,
// of `seed` (none: format_settings). Throws std::runtime_error with the path and errno text on
// failure, interp::Error for a file on disk that no longer reads; the old file stays intact.
void save_settings_atomic(const std::string& path, const Settings& s, const std::string& seed = "");

// Writes `t` into the LinuxCNC .tbl file `path` as update_linuxcnc_tool_table of the table the
// file holds now or, while it does not exist, of `seed` (none: a new table), so that the words,
// comments and line order of a hand-written table survive. Atomic as save_settings_atomic, with
// its errors; a table on disk that no longer reads throws interp::Error "file:line:col: cause".
// Either way `path` keeps its old contents.
void save_tool_table_atomic(const std::string& path, const ToolTable& t,
                            const std::string& seed = "");

// Where SettingsFileLock keeps its lock files: one fixed folder, so that every run on this
// computer finds the same lock for the same settings file whatever its environment, and nothing
// is written beside the settings (a config or test folder).
inline constexpr const char* kSettingsLockDir = "/tmp/cnc-settings-locks";

// An exclusive advisory lock (flock) on one settings file (or tool table) for as long as the
// object lives: a run that may save the file holds it, so that a second run on the same file
// is refused instead of silently overwriting the first one's changes (the last save would win).
// The lock is on a file in `lock_dir` named after the settings file's real path (symbolic links
// resolved), not on the settings file itself, which every save replaces. The holder writes its
// process id into it; the lock file goes when the holder lets go (or dies: the kernel drops the
// lock). Advisory: only programs that take it are kept out.
class SettingsFileLock {
  public:
    // Throws std::runtime_error "PATH: settings file in use by another run (pid N) ..." when
    // held, "PATH: cannot lock settings file: LOCKFILE: cause" when the lock cannot be taken.
    explicit SettingsFileLock(const std::string& path,
                              const std::string& lock_dir = kSettingsLockDir);
    ~SettingsFileLock();
    SettingsFileLock(const SettingsFileLock&) = delete;
    SettingsFileLock& operator=(const SettingsFileLock&) = delete;

    // The lock file for `path` (its real path's last part and a hash of the whole).
    static std::string lock_file_of(const std::string& path,
                                    const std::string& lock_dir = kSettingsLockDir);

  private:
    std::string lock_file_;
    int fd_ = -1;
};

}  // namespace interp
