#include <editline/readline.h>

#include <cstdlib>
#include <cstring>

#include "backends.hpp"
#include "hal/types.hpp"

namespace hal {

namespace {
Backend* g_completion_backend = nullptr;  // readline's completion hook takes no user data
std::vector<std::string> g_candidates;

char* next_candidate(const char* text, int state) {
    static std::size_t index;
    if (state == 0) index = 0;
    std::size_t len = std::strlen(text);
    while (index < g_candidates.size()) {
        const auto& c = g_candidates[index++];
        if (c.compare(0, len, text) == 0) return strdup(c.c_str());
    }
    return nullptr;
}

char** complete(const char* text, int start, int) {
    g_candidates.clear();
    try {
        if (start == 0) {
            g_candidates = g_completion_backend->names("command");
            for (const char* local : {"source", "echo", "loadusr", "waitusr", "exit", "quit"})
                g_candidates.emplace_back(local);
        } else {
            for (const char* kind : {"pin", "param", "sig", "funct", "thread", "comp"})
                for (auto& n : g_completion_backend->names(kind)) g_candidates.push_back(n);
        }
    } catch (...) {
    }
    rl_attempted_completion_over = 1;
    return rl_completion_matches(text, next_candidate);
}
}  // namespace

void interactive(Script& script, Backend& backend, const char* prompt) {
    g_completion_backend = &backend;
    rl_attempted_completion_function = complete;
    int line = 0;
    while (char* raw = readline(prompt)) {
        std::string text(raw);
        std::free(raw);
        ++line;
        if (text.find_first_not_of(" \t") == std::string::npos) continue;
        add_history(text.c_str());
        std::vector<std::string> words;
        try {
            words = script.tokenize(text);
        } catch (const Error&) {
            // run_line below reports it
        }
        if (!words.empty() && (words[0] == "exit" || words[0] == "quit")) break;
        script.run_line(text);
    }
    g_completion_backend = nullptr;
}

}  // namespace hal
