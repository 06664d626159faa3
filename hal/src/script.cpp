#include "hal/script.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include "hal/ini.hpp"
#include "hal/types.hpp"

namespace hal {

Script::Script(Backend& backend) : backend_(backend) {}
Script::~Script() = default;

void Script::load_ini(const std::string& path) { ini_ = std::make_unique<IniFile>(IniFile::load(path)); }

std::string Script::substitute(const std::string& line) const {
    std::string out;
    for (std::size_t i = 0; i < line.size();) {
        char c = line[i];
        if (c == '[') {
            // [SECTION]KEY, or [SECTION](KEY) when the key must be followed by more text.
            auto close = line.find(']', i);
            std::size_t key_begin = close == std::string::npos ? close : close + 1;
            std::size_t key_end = key_begin;
            bool parenthesized = key_begin != std::string::npos && key_begin < line.size() && line[key_begin] == '(';
            if (parenthesized) {
                key_end = line.find(')', key_begin);
                if (key_end == std::string::npos) throw Error("unterminated [SECTION](KEY)");
                ++key_begin;
            } else {
                while (key_end != std::string::npos && key_end < line.size() &&
                       (std::isalnum(static_cast<unsigned char>(line[key_end])) || line[key_end] == '_' ||
                        line[key_end] == '-' || line[key_end] == '.'))
                    ++key_end;
            }
            if (close != std::string::npos && key_end > key_begin) {
                auto section = line.substr(i + 1, close - i - 1);
                auto key = line.substr(key_begin, key_end - key_begin);
                if (!ini_)
                    throw Error(fmt::format("[{}]{} needs an INI file (halrun -i FILE)", section, key));
                auto v = ini_->get(section, key);
                if (!v) throw Error(fmt::format("[{}]{} is not in INI file '{}'", section, key, ini_->path()));
                out += *v;
                i = parenthesized ? key_end + 1 : key_end;
                continue;
            }
        }
        if (c == '$' && i + 1 < line.size()) {
            std::size_t start = i + 1, end;
            bool paren = line[start] == '(';
            if (paren) {
                end = line.find(')', start);
                if (end == std::string::npos) throw Error("unterminated $( in line");
                ++start;
            } else {
                end = start;
                while (end < line.size() && (std::isalnum(static_cast<unsigned char>(line[end])) || line[end] == '_'))
                    ++end;
            }
            auto var = line.substr(start, end - start);
            if (!var.empty()) {
                const char* v = std::getenv(var.c_str());
                if (!v) throw Error(fmt::format("environment variable '{}' is not set", var));
                out += v;
                i = paren ? end + 1 : end;
                continue;
            }
        }
        out += c;
        ++i;
    }
    return out;
}

std::vector<std::string> Script::tokenize(const std::string& raw) const {
    // Comments go before substitution so a '#' inside an INI value is kept.
    std::string line;
    bool quoted = false;
    for (std::size_t i = 0; i < raw.size(); ++i) {
        char c = raw[i];
        if (c == '"') quoted = !quoted;
        if (c == '#' && !quoted && (i == 0 || std::isspace(static_cast<unsigned char>(raw[i - 1])))) break;
        line += c;
    }
    if (quoted) throw Error("unterminated quote");
    line = substitute(line);
    std::vector<std::string> words;
    std::string word;
    bool in_word = false;
    quoted = false;
    for (char c : line) {
        if (c == '"') {
            quoted = !quoted;
            in_word = true;
            continue;
        }
        if (!quoted && std::isspace(static_cast<unsigned char>(c))) {
            if (in_word) words.push_back(word);
            word.clear();
            in_word = false;
            continue;
        }
        word += c;
        in_word = true;
    }
    if (in_word) words.push_back(word);
    return words;
}

void Script::run_words(const std::vector<std::string>& words, std::string& out) {
    const std::string& cmd = words[0];
    // `pin = value` is LinuxCNC's shorthand for setp.
    if (words.size() == 3 && words[1] == "=") {
        backend_.exec({"setp", words[0], words[2]}, out);
        return;
    }
    if (cmd == "quit" || cmd == "exit") {
        quit_ = true;
    } else if (cmd == "echo") {
        std::vector<std::string> rest(words.begin() + 1, words.end());
        out += fmt::format("{}\n", fmt::join(rest, " "));
    } else if (cmd == "source") {
        if (words.size() != 2) throw Error("usage: source FILE");
        // A relative path is looked up beside the sourcing file first, then in the working
        // directory, so a config's files find each other wherever halrun is started.
        std::string path = words[1];
        if (!file_stack_.empty() && !path.empty() && path[0] != '/') {
            auto beside = std::filesystem::path(file_stack_.back()).parent_path() / path;
            if (std::filesystem::exists(beside)) path = beside.string();
        }
        if (!run_file(path)) throw Error(fmt::format("sourced file '{}' failed", words[1]));
    } else if (cmd == "loadusr") {
        cmd_loadusr(words);
    } else if (cmd == "waitusr") {
        cmd_waitusr(words);
    } else {
        backend_.exec(words, out);
    }
}

void Script::execute(const std::string& text, std::string& out) {
    auto words = tokenize(text);
    if (!words.empty()) run_words(words, out);
}

bool Script::run_line(const std::string& text, const std::string& where, int line) {
    std::string out;
    try {
        execute(text, out);
        fmt::print("{}", out);
        std::fflush(stdout);
        return true;
    } catch (const Error& e) {
        fmt::print("{}", out);
        std::fflush(stdout);
        if (line > 0) fmt::print(stderr, "{}:{}: {}\n", where, line, e.what());
        else fmt::print(stderr, "{}: {}\n", where, e.what());
        return false;
    }
}

bool Script::run_file(const std::string& path) {
    if (std::find(file_stack_.begin(), file_stack_.end(), path) != file_stack_.end()) {
        fmt::print(stderr, "{}: sourced from itself\n", path);
        return false;
    }
    std::ifstream in(path);
    if (!in) {
        fmt::print(stderr, "{}: cannot open: {}\n", path, std::strerror(errno));
        return false;
    }
    file_stack_.push_back(path);
    std::string physical, logical;
    int line_no = 0, first_line = 0;
    bool ok = true;
    while (ok && !quit_ && std::getline(in, physical)) {
        ++line_no;
        if (logical.empty()) first_line = line_no;
        if (!physical.empty() && physical.back() == '\r') physical.pop_back();
        if (!physical.empty() && physical.back() == '\\') {
            logical += physical.substr(0, physical.size() - 1) + " ";
            continue;
        }
        logical += physical;
        ok = run_line(logical, path, first_line);
        logical.clear();
    }
    if (ok && !quit_ && !logical.empty()) ok = run_line(logical, path, first_line);
    file_stack_.pop_back();
    if (file_stack_.empty()) quit_ = false;  // quit ends the outermost file, not the session
    return ok;
}

void Script::cmd_loadusr(const std::vector<std::string>& words) {
    bool wait_ready = false, wait_exit = false, ignore_status = false;
    std::string name;
    std::size_t i = 1;
    for (; i < words.size() && words[i].size() > 1 && words[i][0] == '-'; ++i) {
        const auto& opt = words[i];
        if (opt == "-W") wait_ready = true;
        else if (opt == "-w") wait_exit = true;
        else if (opt == "-i") ignore_status = true;
        else if (opt == "-Wn" || opt == "-n") {
            wait_ready = wait_ready || opt == "-Wn";
            if (++i >= words.size()) throw Error(fmt::format("{} needs a component name", opt));
            name = words[i];
        } else {
            throw Error(fmt::format("loadusr: unknown option '{}' (-W, -w, -i, -n NAME, -Wn NAME)", opt));
        }
    }
    if (i >= words.size()) throw Error("usage: loadusr [-W|-w|-i|-Wn NAME] PROGRAM [ARGS...]");
    std::vector<std::string> argv(words.begin() + static_cast<long>(i), words.end());
    if (name.empty()) name = argv[0].substr(argv[0].rfind('/') + 1);
    const std::string program = argv[0];  // as the file wrote it, for messages
    // Our own tools (halsampler, halstreamer, …) come before same-named programs on PATH,
    // e.g. LinuxCNC's, which would attach to the wrong bus.
    if (argv[0].find('/') == std::string::npos) {
        std::error_code ec;
        auto own = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path() / argv[0];
        if (!ec && ::access(own.c_str(), X_OK) == 0) argv[0] = own.string();
    }
    std::fflush(stdout);
    std::fflush(stderr);
    pid_t pid = ::fork();
    if (pid < 0) throw Error(fmt::format("loadusr: fork failed: {}", std::strerror(errno)));
    if (pid == 0) {
        // halrun blocks SIGINT/SIGTERM in its threads to take them in one place; a child must
        // not inherit that mask, or unload and Ctrl-C could never stop it.
        sigset_t none;
        sigemptyset(&none);
        ::sigprocmask(SIG_SETMASK, &none, nullptr);
        std::vector<char*> args;
        for (auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        ::execvp(args[0], args.data());
        fmt::print(stderr, "loadusr: cannot run '{}': {}\n", argv[0], std::strerror(errno));
        ::_exit(127);
    }
    children_[name] = pid;
    auto wait_child = [&]() -> int {
        int status = 0;
        while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
        children_.erase(name);
        return status;
    };
    if (wait_exit) {
        int status = wait_child();
        if (!ignore_status && (!WIFEXITED(status) || WEXITSTATUS(status) != 0))
            throw Error(fmt::format("loadusr: '{}' failed ({})", program,
                                    WIFEXITED(status) ? fmt::format("exit status {}", WEXITSTATUS(status))
                                                      : fmt::format("signal {}", WTERMSIG(status))));
        return;
    }
    if (wait_ready) {
        using namespace std::chrono;
        auto deadline = steady_clock::now() + seconds(30);
        while (!backend_.component_ready(name)) {
            int status = 0;
            if (::waitpid(pid, &status, WNOHANG) == pid) {
                children_.erase(name);
                throw Error(fmt::format("loadusr: '{}' exited before component '{}' became ready", program, name));
            }
            if (steady_clock::now() > deadline) {
                throw Error(fmt::format("loadusr: component '{}' not ready after 30 s", name));
            }
            std::this_thread::sleep_for(milliseconds(5));
        }
    }
}

void Script::cmd_waitusr(const std::vector<std::string>& words) {
    if (words.size() != 2) throw Error("usage: waitusr COMPONENT");
    auto& name = words[1];
    if (auto it = children_.find(name); it != children_.end()) {
        int status = 0;
        while (::waitpid(it->second, &status, 0) < 0 && errno == EINTR) {
        }
        children_.erase(it);
        return;
    }
    if (!backend_.component_exists(name)) throw Error(fmt::format("waitusr: no component '{}'", name));
    while (backend_.component_exists(name)) std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

void Script::terminate_children() {
    for (auto& [name, pid] : children_) ::kill(pid, SIGTERM);
    // A child that ignores SIGTERM for 2 s is killed: shutdown must not hang on it.
    auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    for (auto& [name, pid] : children_) {
        int status;
        while (::waitpid(pid, &status, WNOHANG) == 0) {
            if (std::chrono::steady_clock::now() > deadline) {
                ::kill(pid, SIGKILL);
                ::waitpid(pid, &status, 0);
                break;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
    }
    children_.clear();
}

}  // namespace hal
