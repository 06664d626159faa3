#pragma once
// Program variables: numbered #1…#999 (VAR-01 REC: program-global doubles) and the fixed-cycle
// variables #FC1…#FC50 (VAR-02). Every write during a block goes through an undo log so that a
// rejected block leaves the variables as they were.
#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "interp/block.hpp"

namespace interp {

class Variables {
  public:
    static constexpr int kMaxNumbered = 999;
    static constexpr int kMaxFixedCycle = 50;

    // Reading a numbered variable that was never assigned is an error (it is almost always a
    // typo, and guessing 0 would move the machine somewhere unintended).
    double numbered(int n, const SourceLoc& loc) const;
    std::optional<double> numbered_if_set(int n) const;
    void set_numbered(int n, double v, const SourceLoc& loc);
    // Fixed-cycle variables start at 0 (FC-1: "reserved and zero").
    double fixed_cycle(int n, const SourceLoc& loc) const;
    void set_fixed_cycle(int n, double v, const SourceLoc& loc);

    // Writable named parameters (#FIXEDCALI_REC) assigned by the current block. They are held
    // here until the block has executed, then handed to MachineQuery::write_setting by the
    // interpreter; rollback() drops them. Values in mm for lengths.
    struct NamedWrite {
        std::string_view name;  // points into the static named-parameter table
        double value = 0;
    };
    void set_named(std::string_view name, double value, const SourceLoc& loc);
    std::optional<double> pending_named(std::string_view name) const;
    const std::vector<NamedWrite>& pending_named_writes() const { return named_; }

    // Block transaction: writes after begin() are undone by rollback(), kept by commit().
    void begin();
    void commit();
    void rollback();

    // Forget every value (program start).
    void clear();

  private:
    struct Undo {
        bool fixed_cycle;
        int index;
        double old_value;
        bool old_set;
    };
    std::array<double, kMaxNumbered + 1> numbered_{};
    std::array<bool, kMaxNumbered + 1> numbered_set_{};
    std::array<double, kMaxFixedCycle + 1> fixed_cycle_{};
    std::vector<Undo> undo_;
    std::vector<NamedWrite> named_;
    bool in_block_ = false;
};

}  // namespace interp
