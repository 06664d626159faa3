#include "interp/variables.hpp"

#include <cmath>
#include <string>

namespace interp {

namespace {
void check_finite(double v, const std::string& name, const SourceLoc& loc) {
    if (!std::isfinite(v))
        throw Error(loc, "value assigned to " + name + " is not a finite number");
}
}  // namespace

double Variables::numbered(int n, const SourceLoc& loc) const {
    if (n < 1 || n > kMaxNumbered) {
        throw Error(loc, "variable #" + std::to_string(n) + " is out of range (#1…#" +
                             std::to_string(kMaxNumbered) + ")");
    }
    if (!numbered_set_[n]) {
        throw Error(loc, "variable #" + std::to_string(n) + " is used before it is set");
    }
    return numbered_[n];
}

std::optional<double> Variables::numbered_if_set(int n) const {
    if (n < 1 || n > kMaxNumbered || !numbered_set_[n]) return std::nullopt;
    return numbered_[n];
}

void Variables::set_numbered(int n, double v, const SourceLoc& loc) {
    if (n < 1 || n > kMaxNumbered) {
        throw Error(loc, "variable #" + std::to_string(n) + " is out of range (#1…#" +
                             std::to_string(kMaxNumbered) + ")");
    }
    check_finite(v, "#" + std::to_string(n), loc);
    if (in_block_) undo_.push_back(Undo{false, n, numbered_[n], numbered_set_[n]});
    numbered_[n] = v;
    numbered_set_[n] = true;
}

double Variables::fixed_cycle(int n, const SourceLoc& loc) const {
    if (n < 1 || n > kMaxFixedCycle) {
        throw Error(loc, "fixed-cycle variable #FC" + std::to_string(n) +
                             " is out of range (#FC1…#FC" + std::to_string(kMaxFixedCycle) + ")");
    }
    return fixed_cycle_[n];
}

void Variables::set_fixed_cycle(int n, double v, const SourceLoc& loc) {
    if (n < 1 || n > kMaxFixedCycle) {
        throw Error(loc, "fixed-cycle variable #FC" + std::to_string(n) +
                             " is out of range (#FC1…#FC" + std::to_string(kMaxFixedCycle) + ")");
    }
    check_finite(v, "#FC" + std::to_string(n), loc);
    if (in_block_) undo_.push_back(Undo{true, n, fixed_cycle_[n], true});
    fixed_cycle_[n] = v;
}

void Variables::set_named(std::string_view name, double v, const SourceLoc& loc) {
    check_finite(v, "#" + std::string(name), loc);
    for (NamedWrite& w : named_)
        if (w.name == name) {
            w.value = v;
            return;
        }
    named_.push_back(NamedWrite{name, v});
}

std::optional<double> Variables::pending_named(std::string_view name) const {
    for (const NamedWrite& w : named_)
        if (w.name == name) return w.value;
    return std::nullopt;
}

void Variables::begin() {
    undo_.clear();
    named_.clear();
    in_block_ = true;
}

void Variables::commit() {
    undo_.clear();
    named_.clear();
    in_block_ = false;
}

void Variables::rollback() {
    // Undo newest first so a variable written twice ends at its value before the block.
    for (auto it = undo_.rbegin(); it != undo_.rend(); ++it) {
        if (it->fixed_cycle) {
            fixed_cycle_[it->index] = it->old_value;
        } else {
            numbered_[it->index] = it->old_value;
            numbered_set_[it->index] = it->old_set;
        }
    }
    undo_.clear();
    named_.clear();
    in_block_ = false;
}

void Variables::clear() {
    numbered_.fill(0.0);
    numbered_set_.fill(false);
    fixed_cycle_.fill(0.0);
    undo_.clear();
    named_.clear();
    in_block_ = false;
}

}  // namespace interp
