// The two places a HAL script's bus commands can go.
#pragma once

#include "hal/client.hpp"
#include "hal/script.hpp"
#include "runtime.hpp"

namespace hal {

// In-process: halrun owns the instance.
class LocalBackend : public Backend {
public:
    explicit LocalBackend(Runtime& rt) : rt_(rt) {}
    void exec(const std::vector<std::string>& words, std::string& out) override { rt_.execute(words, out); }
    std::vector<std::string> names(const std::string& kind) override {
        return kind == "command" ? rt_.command_names() : rt_.names(kind);
    }
    bool component_exists(const std::string& name) override { return rt_.component_exists(name); }
    bool component_ready(const std::string& name) override { return rt_.component_ready(name); }

private:
    Runtime& rt_;
};

// Over the instance socket: halcmd.
class RemoteBackend : public Backend {
public:
    explicit RemoteBackend(Connection& c) : conn_(c) {}
    void exec(const std::vector<std::string>& words, std::string& out) override { out += conn_.request(words); }
    std::vector<std::string> names(const std::string& kind) override {
        std::vector<std::string> out;
        std::string all = conn_.request({"@names", kind}), item;
        for (char c : all + "\n") {
            if (c == '\n') {
                if (!item.empty()) out.push_back(item);
                item.clear();
            } else {
                item += c;
            }
        }
        return out;
    }
    bool component_exists(const std::string& name) override { return conn_.request({"@exists", name}) == "1"; }
    bool component_ready(const std::string& name) override { return conn_.request({"@isready", name}) == "1"; }

private:
    Connection& conn_;
};

// Interactive prompt with history and tab completion of commands and names.
void interactive(Script& script, Backend& backend, const char* prompt);

}  // namespace hal
