#pragma once
// Printers for the canonical stream: the native text form and LinuxCNC's `rs274 -g` form, and a
// summary collector for `cnc check` (extents, tools, path length).
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "interp/canon.hpp"

namespace interp {

// One command per line in the native form (to_text); commands from a file other than the first
// one seen are prefixed with that file's name.
class NativePrinter final : public CanonSink {
  public:
    explicit NativePrinter(std::FILE* out) : out_(out) {}
    void emit(const Canon& c) override;

  private:
    std::FILE* out_;
    std::string main_file_;
};

// Prints what LinuxCNC 2.9's `rs274 -g` prints for the subset both interpreters share (G0–G3,
// planes, units, G90/G91, G54–G59, G92, G43/G49, dwell, feed, spindle, coolant, tool change):
// numbered lines "    n N..... CALL(args)", coordinates in work coordinates and program
// units. Commands outside that subset are printed as COMMENT("native: …") so nothing is hidden.
// Known differences are listed in docs/interp.md.
class LinuxCncPrinter final : public CanonSink {
  public:
    explicit LinuxCncPrinter(std::FILE* out) : out_(out) {}
    void emit(const Canon& c) override;
    // Prints the trailing ON_RESET() lines rs274 prints when it exits.
    void finish();

  private:
    void line(const std::string& call);
    void preamble();
    void flush_block();
    void print(const CanonCommand& c);
    void exact_stop_note(const canon::MoveFlags& f);
    std::string axes(const AxisVec& machine) const;
    double unit(double mm) const { return mm / mm_per_unit_; }

    std::FILE* out_;
    int n_ = 0;
    bool started_ = false;
    double mm_per_unit_ = 1.0;
    canon::Offsets offsets_;
    std::array<double, 3> tool_mm_{};
    bool flood_ = false;
    int block_line_ = -1;
    std::vector<CanonCommand> block_;  // one source line's commands, printed together
};

// Collects what `cnc check` reports.
class SummarySink final : public CanonSink {
  public:
    void emit(const Canon& c) override;

    bool any_motion() const { return moves_ > 0; }
    std::array<double, 3> min_mm() const { return min_; }
    std::array<double, 3> max_mm() const { return max_; }
    const std::set<int>& tools() const { return tools_; }
    double feed_length_mm() const { return feed_len_; }
    double rapid_length_mm() const { return rapid_len_; }
    // Feed moves at their programmed feed plus dwells; rapids are not timed (machine dependent).
    double feed_time_s() const { return feed_time_; }
    int moves() const { return moves_; }

  private:
    void extend(double x, double y, double z);
    void line_to(const AxisVec& end, bool rapid);
    void arc(const canon::Arc& a);

    AxisVec pos_{};
    double feed_mm_s_ = 0;
    std::array<double, 3> min_{}, max_{};
    std::set<int> tools_;
    double feed_len_ = 0, rapid_len_ = 0, feed_time_ = 0;
    int moves_ = 0;
};

// Prints warnings as "file:line:col: warning: text", one per line: the front end's (as a
// WarningSink) and the back end's canon::Warning commands (as a CanonSink; other commands are
// ignored, so put it beside the real consumer with a TeeSink).
class WarningPrinter final : public CanonSink, public WarningSink {
  public:
    explicit WarningPrinter(std::FILE* out) : out_(out) {}
    void emit(const Canon& c) override;
    void warning(const SourceLoc& loc, const std::string& text) override;
    int count() const { return count_; }

  private:
    std::FILE* out_;
    int count_ = 0;
};

// Fans one stream out to several sinks.
class TeeSink final : public CanonSink {
  public:
    void add(CanonSink& s) { sinks_.push_back(&s); }
    void emit(const Canon& c) override {
        for (CanonSink* s : sinks_) s->emit(c);
    }

  private:
    std::vector<CanonSink*> sinks_;
};

}  // namespace interp
