#include "clients/remote/progress_line.h"

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;

pb::JobProgress Progress(int measured, int issued, int pending, int budget_left) {
  pb::JobProgress p;
  p.set_measured(measured);
  p.set_issued(issued);
  p.set_pending(pending);
  p.set_budget_left(budget_left);
  return p;
}

TEST(ProgressFractionTest, ShareOfKnownSitesWithoutBudget) {
  EXPECT_DOUBLE_EQ(ProgressFraction(Progress(30, 10, 60, -1)), 0.3);
}

TEST(ProgressFractionTest, BudgetCapsTheKnownWork) {
  // 100 known sites but only 20 more may be issued (budget_left = budget -
  // measured - issued): 30 measured of 30 + 10 issued + 20 = 60.
  EXPECT_DOUBLE_EQ(ProgressFraction(Progress(30, 10, 60, 20)), 0.5);
}

TEST(ProgressFractionTest, IssuedSitesAreWorkLeftWhenTheBudgetIsHeld) {
  // The budget is held by issued drags (none more may be issued) while sites
  // wait: not done (was reported 100 %).
  EXPECT_DOUBLE_EQ(ProgressFraction(Progress(160, 8, 20, 0)), 160.0 / 168.0);
  EXPECT_NE(FormatProgressLine(Progress(160, 8, 20, 0), 0).find(" 95%  160/168 measured"), std::string::npos)
      << FormatProgressLine(Progress(160, 8, 20, 0), 0);
}

TEST(ProgressFractionTest, CompleteOrEmptyIsFull) {
  pb::JobProgress p = Progress(5, 0, 7, -1);
  p.set_complete(true);
  EXPECT_DOUBLE_EQ(ProgressFraction(p), 1.0);
  EXPECT_DOUBLE_EQ(ProgressFraction(Progress(0, 0, 0, -1)), 1.0);
}

TEST(FormatProgressLineTest, BarCountsAndLevels) {
  pb::JobProgress p = Progress(42, 6, 45, -1);
  pb::LevelProgress* l0 = p.add_levels();
  l0->set_level(0);
  l0->set_measured(42);
  pb::LevelProgress* l1 = p.add_levels();
  l1->set_level(1);
  l1->set_pending(45);
  EXPECT_EQ(FormatProgressLine(p, 10),
            "[####------]  45%  42/93 measured, 6 issued, 45 pending, 0 failed | L0 42/0 L1 0/45");
  EXPECT_EQ(FormatProgressLine(p, 0), " 45%  42/93 measured, 6 issued, 45 pending, 0 failed | L0 42/0 L1 0/45");
}

TEST(FormatProgressLineTest, MentionsBudgetAndSkipped) {
  pb::JobProgress p = Progress(10, 0, 0, 5);
  p.set_skipped(3);
  EXPECT_EQ(FormatProgressLine(p, 0), "100%  10/10 measured, 0 issued, 0 pending, 0 failed, 3 skipped, budget left 5");
  p.set_leased(0);
  EXPECT_EQ(FormatProgressLine(p, 0),
            "100%  10/10 measured, 0 issued (0 at rigs), 0 pending, 0 failed, 3 skipped, budget left 5");
}

std::string Captured(bool redraw, const std::vector<std::string>& lines, int columns = 0) {
  std::FILE* f = std::tmpfile();
  {
    ProgressDisplay display(f, redraw, columns);
    for (const std::string& l : lines) display.Show(l);
  }
  std::rewind(f);
  std::string out;
  char buf[256];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
  std::fclose(f);
  return out;
}

TEST(ProgressDisplayTest, PlainLinesSkipRepeats) {
  EXPECT_EQ(Captured(false, {"a", "a", "b"}), "a\nb\n");
}

TEST(ProgressDisplayTest, RedrawsInPlaceAndEndsTheLine) {
  EXPECT_EQ(Captured(true, {"a", "a", "b"}), "\ra\x1b[K\rb\x1b[K\n");
}

TEST(FitToWidthTest, CutsOnlyWhatDoesNotFit) {
  EXPECT_EQ(FitToWidth("abcdef", 6), "abcdef");
  EXPECT_EQ(FitToWidth("abcdefg", 6), "abc...");
  EXPECT_EQ(FitToWidth("abcdefg", 2), "ab");
  EXPECT_EQ(FitToWidth("abcdefg", 0), "abcdefg");
}

// The widest line the rig prints: its id, a 20-character bar, a job with
// leases, failures, skipped sites, a budget and four levels. On an 80-column
// terminal every redraw must stay on one row (at most 79 characters between
// the '\r' and the erase), or each update leaves a clipped line behind.
TEST(ProgressDisplayTest, FitsAnEightyColumnTerminal) {
  pb::JobProgress p = Progress(1234, 16, 20769, 5000);
  p.set_leased(16);
  p.set_failed(12);
  p.set_skipped(40);
  for (int level = 0; level < 4; ++level) {
    pb::LevelProgress* l = p.add_levels();
    l->set_level(level);
    l->set_measured(300 * level);
    l->set_pending(5000 + level);
  }
  const std::string line = "sim-bottle-123456 " + FormatProgressLine(p, 20);
  ASSERT_GT(line.size(), 80u) << "the test needs a line wider than the terminal";
  const std::string shown = Captured(true, {line}, 80);
  ASSERT_EQ(shown.front(), '\r');
  const std::size_t erase = shown.find("\x1b[K");
  ASSERT_NE(erase, std::string::npos);
  const std::string row = shown.substr(1, erase - 1);
  EXPECT_EQ(row.size(), 79u);
  EXPECT_EQ(row.substr(0, 40), line.substr(0, 40));  // the start (bar, percentage, counts) is kept
  EXPECT_EQ(row.substr(row.size() - 3), "...");
}

TEST(ProgressDisplayTest, PlainLinesAreNotCut) {
  const std::string line(120, 'x');
  EXPECT_EQ(Captured(false, {line}, 80), line + "\n");
}

TEST(TerminalColumnsTest, ColumnsVariableThenEighty) {
  std::FILE* f = std::tmpfile();  // not a terminal: TIOCGWINSZ fails
  ASSERT_NE(f, nullptr);
  const char* saved = std::getenv("COLUMNS");
  const std::string restore = saved ? saved : "";
  ::setenv("COLUMNS", "132", 1);
  EXPECT_EQ(TerminalColumns(f), 132);
  ::setenv("COLUMNS", "wide", 1);
  EXPECT_EQ(TerminalColumns(f), 80);
  ::unsetenv("COLUMNS");
  EXPECT_EQ(TerminalColumns(f), 80);
  if (saved) ::setenv("COLUMNS", restore.c_str(), 1);
  std::fclose(f);
}

}  // namespace
}  // namespace surfmap::cli
