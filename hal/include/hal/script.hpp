// The HAL-file language front end: reads files or lines, joins `\` continuations, drops
// `#` comments, substitutes `[SECTION]KEY` from the INI file and `$VAR` / `$(VAR)` from the
// environment, tokenizes, runs the commands that belong to the reading process (source,
// echo, loadusr, waitusr) and hands every bus command to a Backend: the runtime in-process
// (halrun) or over the instance socket (halcmd). Every error reads `file:line: message`.
#pragma once

#include <sys/types.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace hal {

class Backend {
public:
    virtual ~Backend() = default;
    // Runs one bus command; throws hal::Error. Output lines are appended to `out`.
    virtual void exec(const std::vector<std::string>& words, std::string& out) = 0;
    virtual std::vector<std::string> names(const std::string& kind) = 0;
    virtual bool component_exists(const std::string& name) = 0;
    virtual bool component_ready(const std::string& name) = 0;
};

class IniFile;  // hal/ini.hpp

class Script {
public:
    explicit Script(Backend& backend);
    ~Script();
    // Loads the INI file used for [SECTION]KEY substitution; throws hal::Error.
    void load_ini(const std::string& path);
    // Runs a file; stops at the first failing line. Returns false after printing the error.
    bool run_file(const std::string& path);
    // Runs one logical line (interactive use); prints output, returns false on error.
    bool run_line(const std::string& text, const std::string& where = "<stdin>", int line = 0);
    // Runs one logical line, appending its output; throws hal::Error. Prints nothing.
    void execute(const std::string& text, std::string& out);
    // Splits a line into words, after substitution. Throws hal::Error.
    std::vector<std::string> tokenize(const std::string& line) const;
    // Process ids of loadusr children still running (halrun ends them on exit).
    const std::map<std::string, pid_t>& children() const noexcept { return children_; }
    void terminate_children();

private:
    void run_words(const std::vector<std::string>& words, std::string& out);
    void cmd_loadusr(const std::vector<std::string>& words);
    void cmd_waitusr(const std::vector<std::string>& words);
    std::string substitute(const std::string& line) const;

    Backend& backend_;
    std::unique_ptr<IniFile> ini_;
    std::vector<std::string> file_stack_;  // for `source` cycles
    std::map<std::string, pid_t> children_;  // component name -> pid
    bool quit_ = false;  // `quit` or `exit` read from a file
};

}  // namespace hal
