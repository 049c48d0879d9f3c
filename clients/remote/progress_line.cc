#include "clients/remote/progress_line.h"

#include <algorithm>
#include <cmath>

#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdlib>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace surfmap::cli {

namespace pb = ::surfmap::v1;

namespace {

// Measured, issued, and the pending sites the budget still allows:
// budget_left is what may still be issued (budget - measured - issued), so
// issued sites are work to do whatever the budget says.
long long KnownWork(const pb::JobProgress& progress) {
  long long pending = progress.pending();
  if (progress.budget_left() >= 0) pending = std::min<long long>(pending, progress.budget_left());
  return static_cast<long long>(progress.measured()) + progress.issued() + pending;
}

}  // namespace

double ProgressFraction(const pb::JobProgress& progress) {
  if (progress.complete()) return 1.0;
  const long long known = KnownWork(progress);
  if (known <= 0) return 1.0;
  return std::clamp(static_cast<double>(progress.measured()) / static_cast<double>(known), 0.0, 1.0);
}

std::string FormatProgressLine(const pb::JobProgress& progress, int bar_width) {
  const double fraction = ProgressFraction(progress);
  std::string line;
  if (bar_width > 0) {
    const int filled = std::clamp(static_cast<int>(std::floor(fraction * bar_width + 1e-9)), 0, bar_width);
    line = absl::StrCat("[", std::string(filled, '#'), std::string(bar_width - filled, '-'), "] ");
  }
  const long long known = KnownWork(progress);
  absl::StrAppendFormat(&line, "%3d%%  %d/%d measured, %d issued", static_cast<int>(std::floor(fraction * 100.0 + 1e-9)),
                        progress.measured(), known, progress.issued());
  // issued = queued for a rig or leased; leased = held by a rig right now.
  if (progress.has_leased()) absl::StrAppendFormat(&line, " (%d at rigs)", progress.leased());
  absl::StrAppendFormat(&line, ", %d pending, %d failed", progress.pending(), progress.failed());
  if (progress.skipped() > 0) absl::StrAppendFormat(&line, ", %d skipped", progress.skipped());
  if (progress.budget_left() >= 0) absl::StrAppendFormat(&line, ", budget left %d", progress.budget_left());
  if (progress.levels_size() > 0) {
    line += " |";
    for (const pb::LevelProgress& level : progress.levels()) {
      absl::StrAppendFormat(&line, " L%d %d/%d", level.level(), level.measured(), level.pending());
    }
  }
  return line;
}

std::string FitToWidth(std::string_view line, int columns) {
  if (columns <= 0 || line.size() <= static_cast<std::size_t>(columns)) return std::string(line);
  constexpr std::string_view kCut = "...";
  if (columns <= static_cast<int>(kCut.size())) return std::string(line.substr(0, columns));
  std::string cut(line.substr(0, columns - kCut.size()));
  cut += kCut;
  return cut;
}

int TerminalColumns(std::FILE* stream) {
  struct winsize size {};
  if (::ioctl(::fileno(stream), TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  if (const char* env = std::getenv("COLUMNS")) {
    int columns = 0;
    if (absl::SimpleAtoi(env, &columns) && columns > 0) return columns;
  }
  return 80;
}

std::string_view JobStateName(pb::JobState state) {
  switch (state) {
    case pb::JOB_STATE_RUNNING: return "RUNNING";
    case pb::JOB_STATE_PAUSED: return "PAUSED";
    case pb::JOB_STATE_COMPLETED: return "COMPLETED";
    case pb::JOB_STATE_CANCELLED: return "CANCELLED";
    default: return "UNSPECIFIED";
  }
}

void ProgressDisplay::Show(const std::string& line) {
  if (line == last_) return;
  if (redraw_) {
    // \x1b[K erases what a longer previous line left behind.
    const int columns = columns_ > 0 ? columns_ : TerminalColumns(out_);
    std::fprintf(out_, "\r%s\x1b[K", FitToWidth(line, columns - 1).c_str());
    line_open_ = true;
  } else {
    std::fprintf(out_, "%s\n", line.c_str());
  }
  std::fflush(out_);
  last_ = line;
}

void ProgressDisplay::Finish() {
  if (line_open_) {
    std::fputc('\n', out_);
    std::fflush(out_);
    line_open_ = false;
  }
}

bool ProgressDisplay::IsTerminal(std::FILE* stream) { return ::isatty(::fileno(stream)) == 1; }

}  // namespace surfmap::cli
