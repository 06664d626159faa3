#include "kins_link.hpp"

#include <dlfcn.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <link.h>

#include <stdexcept>
#include <vector>

#include "hal/types.hpp"

namespace motioncomp {
namespace {

std::vector<std::string> loaded_objects() {
    std::vector<std::string> paths;
    dl_iterate_phdr(
        [](dl_phdr_info* info, std::size_t, void* out) {
            if (info->dlpi_name && *info->dlpi_name)
                static_cast<std::vector<std::string>*>(out)->emplace_back(info->dlpi_name);
            return 0;
        },
        &paths);
    return paths;
}

// A loaded kinematics module: a dlopen reference to it and its entry point.
struct Module {
    void* library;
    const motion::KinematicsModule* entry;
};

// Every kinematics module loaded in this process (HAL loads components with RTLD_LOCAL, so
// their entry points are reached through a handle of their own, not the global scope).
std::vector<Module> kinematics_modules() {
    std::vector<Module> modules;
    for (const std::string& path : loaded_objects()) {
        void* lib = ::dlopen(path.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_LOCAL);
        if (!lib) continue;
        using Entry = const motion::KinematicsModule* (*)();
        auto entry = reinterpret_cast<Entry>(::dlsym(lib, motion::kKinematicsEntryPoint));
        const motion::KinematicsModule* m = entry ? entry() : nullptr;
        bool seen = false;
        for (const Module& k : modules) seen = seen || k.entry == m;
        if (!m || seen) {
            ::dlclose(lib);
            continue;
        }
        if (m->abi_version != motion::kKinematicsAbiVersion) {
            ::dlclose(lib);
            for (const Module& k : modules) ::dlclose(k.library);
            throw hal::Error(
                fmt::format("{} was built for kinematics ABI {}, this motion is ABI {}; rebuild it",
                            path, m->abi_version, motion::kKinematicsAbiVersion));
        }
        modules.push_back({lib, m});
    }
    return modules;
}

}  // namespace

KinsLink KinsLink::builtin(std::string_view coordinates) {
    KinsLink link;
    link.name_ = "trivial";
    try {
        link.kins_ = std::make_unique<motion::TrivialKinematics>(coordinates);
    } catch (const std::invalid_argument& e) {
        throw hal::Error(e.what());
    }
    return link;
}

KinsLink KinsLink::find(std::string_view name) {
    std::vector<Module> modules = kinematics_modules();
    KinsLink link;
    link.name_ = std::string(name);
    std::vector<std::string> offered;
    for (const Module& m : modules) {
        if (!link.source_) {
            if (auto source = m.entry->find(name)) {
                link.source_ = std::move(source);
                link.library_ = m.library;
                continue;
            }
        }
        for (const std::string& inst : m.entry->instances())
            offered.push_back(fmt::format("{} ({})", inst, m.entry->name));
        ::dlclose(m.library);
    }
    if (!link.source_) {
        const std::string loaded = offered.empty()
                                       ? "none is loaded"
                                       : fmt::format("loaded: {}", fmt::join(offered, ", "));
        throw hal::Error(fmt::format(
            "kins={}: no kinematics instance or module of that name ({}); load the machine's "
            "kinematics before motion, e.g. `loadrt kins_corexy names=kins` then `loadrt motion "
            "kins=kins`",
            name, loaded));
    }
    link.kins_ = link.source_->make();
    return link;
}

KinsLink KinsLink::automatic(std::string_view coordinates) {
    std::vector<Module> modules = kinematics_modules();
    std::vector<std::string> offered;
    for (const Module& m : modules) {
        for (const std::string& inst : m.entry->instances())
            offered.push_back(fmt::format("{} ({})", inst, m.entry->name));
        ::dlclose(m.library);
    }
    if (offered.empty()) return builtin(coordinates);
    if (offered.size() > 1)
        throw hal::Error(fmt::format(
            "kins=auto: {} kinematics instances are loaded ({}); name the machine's with kins=NAME",
            offered.size(), fmt::join(offered, ", ")));
    return find(offered.front().substr(0, offered.front().find(' ')));
}

bool KinsLink::keep_first_joints_of_identity(std::size_t n) {
    if (!kins_ || kins_->name() != "trivial") return false;
    const auto axes = kins_->joint_axes();
    if (axes.size() != static_cast<std::size_t>(motion::kAxes) || n < 1 || n >= axes.size())
        return false;
    for (std::size_t j = 0; j < axes.size(); ++j)
        if (axes[j] != static_cast<int>(j)) return false;
    kins_ = std::make_unique<motion::TrivialKinematics>(std::string("XYZABCUVW").substr(0, n));
    return true;
}

std::unique_ptr<PlanningKinematics> KinsLink::planning_copy() const {
    // Trivial kinematics have no parameters, and keep_first_joints_of_identity() may have cut
    // the module's nine joints down: build the same joint list directly.
    if (source_ && kins_->name() != "trivial") {
        std::unique_ptr<motion::Kinematics> k = source_->make();
        source_->refresh(*k);  // an unloaded instance leaves make()'s defaults, like kins()
        return std::make_unique<PlanningKinematics>(source_, std::move(k));
    }
    // The same joint-to-axis list (a gantry's XYYZ included).
    std::string letters;
    for (int axis : kins_->joint_axes()) letters += "XYZABCUVW"[axis];
    return std::make_unique<PlanningKinematics>(
        nullptr, std::make_unique<motion::TrivialKinematics>(letters));
}

KinsLink::KinsLink(KinsLink&& o) noexcept
    : name_(std::move(o.name_)),
      library_(o.library_),
      source_(std::move(o.source_)),
      kins_(std::move(o.kins_)) {
    o.library_ = nullptr;
}

KinsLink::~KinsLink() {
    // The kinematics and the source were built by the module's code: free them before the
    // reference that keeps that code mapped.
    kins_.reset();
    source_.reset();
    if (library_) ::dlclose(library_);
}

}  // namespace motioncomp
