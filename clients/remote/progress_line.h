// The one-line progress display of `surfmap watch` and `surfmap-rig`:
//
//   [#########-----------]  45%  42/93 measured, 6 issued, 45 pending, 0 failed | L0 42/0 L1 0/45
//
// Per level: measured/pending. The percentage is of the known work (measured
// + issued + pending sites), capped by the budget when the job has one: an
// adaptive plan discovers new sites as it refines, so the bar can move back.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

#include "proto/surfmap/v1/surfmap.pb.h"

namespace surfmap::cli {

// Measured share of the known work in [0, 1]: measured / min(measured +
// issued + pending, measured + budget_left) (budget_left < 0 = unlimited);
// 1 when the job is complete or has no work at all.
double ProgressFraction(const surfmap::v1::JobProgress& progress);

// The line above (no newline); bar_width >= 0 characters inside the brackets
// (0 = no bar).
std::string FormatProgressLine(const surfmap::v1::JobProgress& progress, int bar_width = 20);

// `line` cut to at most `columns` characters, ending in "..." when cut
// (columns <= 0: unchanged). The line's start (percentage, counts) is what
// matters; the per-level tail is what goes.
std::string FitToWidth(std::string_view line, int columns);

// The width of the terminal behind `stream` (ioctl TIOCGWINSZ), else
// $COLUMNS when it is a positive number, else 80.
int TerminalColumns(std::FILE* stream);

// "RUNNING", "PAUSED", "COMPLETED", "CANCELLED" (or "UNSPECIFIED").
std::string_view JobStateName(surfmap::v1::JobState state);

// Shows successive progress lines: redrawn in place with '\r' (and erased to
// the end of the line) on a terminal; otherwise one plain line per change, so
// logs stay readable. Not thread-safe.
//
// A redrawn line is cut to the terminal's width minus one: a line that wraps
// cannot be redrawn by '\r' (each update would leave a clipped line behind),
// and one that fills the last column leaves some terminals about to wrap.
class ProgressDisplay {
 public:
  // columns > 0 fixes the width (tests); 0 asks TerminalColumns(out) at each
  // line, so a resized terminal is followed.
  ProgressDisplay(std::FILE* out, bool redraw_in_place, int columns = 0)
      : out_(out), redraw_(redraw_in_place), columns_(columns) {}
  ~ProgressDisplay() { Finish(); }
  ProgressDisplay(const ProgressDisplay&) = delete;
  ProgressDisplay& operator=(const ProgressDisplay&) = delete;

  // Shows `line` unless it equals the last one shown.
  void Show(const std::string& line);
  // Ends a redrawn line with a newline (so later output starts on its own line).
  void Finish();

  // Whether `stream` is a terminal.
  static bool IsTerminal(std::FILE* stream);

 private:
  std::FILE* out_;
  bool redraw_;
  int columns_;
  bool line_open_ = false;
  std::string last_;
};

}  // namespace surfmap::cli
