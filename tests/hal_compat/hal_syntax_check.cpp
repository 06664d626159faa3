// hal_syntax_check: reads HAL files the way halrun does (continuations, comments, quotes,
// [SECTION]KEY and $ENV substitution) without running them, and reports every line whose
// words do not tokenize or whose command our runtime does not have. Used by the LinuxCNC
// compatibility survey (scripts/compat/survey.sh) to find syntax gaps in files that cannot be
// loaded for other reasons (components we do not ship).
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "hal/script.hpp"
#include "runtime.hpp"

namespace {

// Tokenizing needs no bus: a backend that refuses everything is enough.
class NoBackend : public hal::Backend {
  public:
    void exec(const std::vector<std::string>&, std::string&) override {
        throw hal::Error("syntax check only");
    }
    std::vector<std::string> names(const std::string&) override { return {}; }
    bool component_exists(const std::string&) override { return false; }
    bool component_ready(const std::string&) override { return false; }
};

// The commands the HAL-language front end runs itself rather than handing to the runtime.
const std::set<std::string> kScriptCommands = {"echo", "source", "loadusr", "waitusr"};

struct LogicalLine {
    int first_line;
    std::string text;
};

// Same joining rule as hal::Script::run_file: a trailing backslash continues the line.
std::vector<LogicalLine> read_logical_lines(std::istream& in) {
    std::vector<LogicalLine> lines;
    std::string physical, logical;
    int line_no = 0, first = 0;
    while (std::getline(in, physical)) {
        ++line_no;
        if (logical.empty()) first = line_no;
        if (!physical.empty() && physical.back() == '\r') physical.pop_back();
        if (!physical.empty() && physical.back() == '\\') {
            logical += physical.substr(0, physical.size() - 1) + " ";
            continue;
        }
        lines.push_back({first, logical + physical});
        logical.clear();
    }
    if (!logical.empty()) lines.push_back({first, logical});
    return lines;
}

int check_file(const std::string& path, const hal::Script& script, const hal::Runtime& runtime) {
    std::ifstream in(path);
    if (!in) {
        fmt::print("{}: cannot open\n", path);
        return 1;
    }
    int problems = 0;
    for (const auto& line : read_logical_lines(in)) {
        try {
            auto words = script.tokenize(line.text);
            if (words.empty()) continue;
            if (!runtime.is_bus_command(words[0]) && !kScriptCommands.count(words[0]))
                throw hal::Error(fmt::format("unknown command '{}'", words[0]));
            // LinuxCNC also substitutes the [SECTION](KEY) spelling; a survivor means we did not.
            static const std::regex ini_ref(R"(\[[A-Za-z0-9_]+\](\([A-Za-z0-9_]+\)))");
            for (const auto& w : words)
                if (std::smatch m; std::regex_search(w, m, ini_ref))
                    throw hal::Error(fmt::format("'{}' left unsubstituted in '{}'", m.str(), w));
        } catch (const hal::Error& e) {
            fmt::print("{}:{}: {}\n", path, line.first_line, e.what());
            ++problems;
        }
    }
    return problems;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"hal_syntax_check: report HAL lines our halrun cannot tokenize or does not know"};
    std::string ini;
    std::vector<std::string> files;
    app.add_option("-i,--ini", ini, "INI file for [SECTION]KEY substitution");
    app.add_option("files", files, "HAL files")->required();
    CLI11_PARSE(app, argc, argv);
    try {
        hal::Runtime::Options options;
        options.instance = fmt::format("syntax-check-{}", ::getpid());
        options.sim_clock = true;
        options.segment_bytes = 1u << 20;
        hal::Runtime runtime(options);
        NoBackend backend;
        hal::Script script(backend);
        if (!ini.empty()) script.load_ini(ini);
        int problems = 0;
        for (const auto& f : files) problems += check_file(f, script, runtime);
        runtime.shutdown();
        return problems == 0 ? 0 : 1;
    } catch (const hal::Error& e) {
        fmt::print("hal_syntax_check: {}\n", e.what());
        return 2;
    }
}
