#include "clients/rig/trace_spool.h"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include "clients/rig/test_dir_for_test.h"

namespace surfmap::rig {
namespace {

namespace fs = std::filesystem;

DragTrace SmallTrace(double mu = 0.3) {
  DragTrace trace;
  const DragPhase phases[] = {DragPhase::kForward, DragPhase::kForward, DragPhase::kPause, DragPhase::kReverse,
                              DragPhase::kReverse};
  for (int i = 0; i < 5; ++i) {
    DragSample s;
    s.t = 0.01 * i;
    s.position = Eigen::Vector3d(i < 2 ? i : 4 - i, 0, 0);
    s.force = Eigen::Vector3d(i < 2 ? -mu * 5 : mu * 5, 0, 5);
    s.phase = phases[i];
    trace.samples.push_back(s);
  }
  return trace;
}

SpoolHeader Header(int64_t command_id, int64_t measured_ms) {
  SpoolHeader h;
  h.command_id = command_id;
  h.job_id = 1;
  h.attempt = 1;
  h.rig_id = "rig-a";
  h.measured_unix_ms = measured_ms;
  return h;
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

TEST(TraceSpoolTest, AddListReadRemove) {
  TestDir dir;
  auto spool = TraceSpool::Open(dir.path() / "spool" / "rig-a");
  ASSERT_TRUE(spool.ok()) << spool.status();
  EXPECT_TRUE(fs::is_directory((*spool)->rejected_dir()));
  auto second = (*spool)->Add(Header(8, 2000), SmallTrace());
  auto first = (*spool)->Add(Header(9, 1000), SmallTrace());
  ASSERT_TRUE(first.ok() && second.ok()) << first.status() << second.status();
  EXPECT_EQ(first->filename(), "0000000001000-command-9.trace.csv");
  auto pending = (*spool)->Pending();
  ASSERT_TRUE(pending.ok());
  EXPECT_EQ(*pending, (std::vector<fs::path>{*first, *second})) << "oldest first";
  auto read = (*spool)->Read(*second);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->header.command_id, 8);
  EXPECT_EQ(read->trace.samples.size(), 5u);
  ASSERT_TRUE((*spool)->Remove(*first).ok());
  EXPECT_EQ(*(*spool)->Pending(), (std::vector<fs::path>{*second}));
  EXPECT_EQ((*spool)->Read(*first).status().code(), absl::StatusCode::kNotFound);
}

TEST(TraceSpoolTest, TheSameCommandTwiceGetsTwoFiles) {
  TestDir dir;
  auto spool = TraceSpool::Open(dir.path());
  ASSERT_TRUE(spool.ok());
  auto a = (*spool)->Add(Header(5, 1000), SmallTrace(0.3));
  auto b = (*spool)->Add(Header(5, 1000), SmallTrace(0.4));
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NE(*a, *b);
  EXPECT_EQ(b->filename(), "0000000001000-command-5-2.trace.csv");
  EXPECT_EQ((*spool)->Pending()->size(), 2u);
}

TEST(TraceSpoolTest, RejectMovesTheFileAndKeepsTheReason) {
  TestDir dir;
  auto spool = TraceSpool::Open(dir.path());
  ASSERT_TRUE(spool.ok());
  auto file = (*spool)->Add(Header(5, 1000), SmallTrace());
  ASSERT_TRUE(file.ok());
  const std::string content = ReadText(*file);
  auto moved = (*spool)->Reject(*file, "ALREADY_EXISTS: command 5 was measured by rig 'b'");
  ASSERT_TRUE(moved.ok()) << moved.status();
  EXPECT_EQ(*moved, (*spool)->rejected_dir() / file->filename());
  EXPECT_FALSE(fs::exists(*file));
  EXPECT_EQ(ReadText(*moved), content);
  const std::string reason = ReadText(moved->string() + ".reason");
  EXPECT_EQ(reason.rfind("ALREADY_EXISTS: command 5 was measured by rig 'b'\nrejected_unix_ms: ", 0), 0u) << reason;
  EXPECT_TRUE((*spool)->Pending()->empty());
  // Only the spool's own files.
  EXPECT_EQ((*spool)->Reject(*moved, "again").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ((*spool)->Remove(dir.path() / "other" / "elsewhere.trace.csv").code(), absl::StatusCode::kInvalidArgument);
}

TEST(TraceSpoolTest, AnInvalidTraceGoesStraightToRejected) {
  TestDir dir;
  auto spool = TraceSpool::Open(dir.path());
  ASSERT_TRUE(spool.ok());
  DragTrace trace = SmallTrace();
  trace.samples[1].force.x() = std::nan("");
  auto file = (*spool)->Add(Header(6, 1000), trace);
  ASSERT_EQ(file.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(file.status().message()).find("kept in " + (*spool)->rejected_dir().string()),
            std::string::npos)
      << file.status();
  EXPECT_TRUE((*spool)->Pending()->empty());
  const fs::path kept = (*spool)->rejected_dir() / "0000000001000-command-6.trace.csv";
  EXPECT_TRUE(fs::exists(kept));
  EXPECT_EQ(ReadText(kept.string() + ".reason").rfind("not submitted: the trace is invalid: ", 0), 0u);
}

TEST(TraceSpoolTest, OneProcessAtATime) {
  TestDir dir;
  auto first = TraceSpool::Open(dir.path());
  ASSERT_TRUE(first.ok());
  // flock locks belong to the open file: a second Open in this process
  // conflicts just as another process would.
  auto second = TraceSpool::Open(dir.path());
  EXPECT_EQ(second.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(std::string(second.status().message()).find("is in use by another rig process"), std::string::npos);
  first->reset();
  EXPECT_TRUE(TraceSpool::Open(dir.path()).ok()) << "the lock goes with the spool";
}

TEST(TraceSpoolTest, OpenDeletesTempFilesOfAnInterruptedWrite) {
  TestDir dir;
  { std::ofstream(dir.path() / ".tmp-0000000001000-command-3.trace.csv.123") << "half a trace"; }
  { std::ofstream(dir.path() / "notes.txt") << "not ours"; }
  auto spool = TraceSpool::Open(dir.path());
  ASSERT_TRUE(spool.ok());
  EXPECT_FALSE(fs::exists(dir.path() / ".tmp-0000000001000-command-3.trace.csv.123"));
  EXPECT_TRUE(fs::exists(dir.path() / "notes.txt")) << "other files are left alone";
  EXPECT_TRUE((*spool)->Pending()->empty());
}

TEST(TraceSpoolTest, RemoveDirectoriesIfEmptyOnlyWhenEmpty) {
  TestDir dir;
  {
    auto spool = TraceSpool::Open(dir.path() / "a");
    ASSERT_TRUE(spool.ok());
    (*spool)->RemoveDirectoriesIfEmpty();
  }
  EXPECT_FALSE(fs::exists(dir.path() / "a"));
  auto spool = TraceSpool::Open(dir.path() / "b");
  ASSERT_TRUE(spool.ok());
  ASSERT_TRUE((*spool)->Add(Header(1, 1), SmallTrace()).ok());
  (*spool)->RemoveDirectoriesIfEmpty();
  EXPECT_TRUE(fs::exists(dir.path() / "b"));
  EXPECT_FALSE(fs::exists(dir.path() / "b" / "rejected")) << "the empty rejected/ goes";
}

TEST(TraceSpoolTest, RigIdsBecomeOnePathComponent) {
  EXPECT_EQ(RigIdPathComponent("lab-arm_1.b"), "lab-arm_1.b");
  EXPECT_EQ(RigIdPathComponent("lab/arm 1"), "lab%2Farm%201");
  EXPECT_EQ(RigIdPathComponent(".."), "%2E%2E");
  EXPECT_EQ(RigIdPathComponent("é"), "%C3%A9");
}

TEST(TraceSpoolTest, DefaultDirFollowsXdgStateHome) {
  const char* old_xdg = std::getenv("XDG_STATE_HOME");
  const std::string saved_xdg = old_xdg ? old_xdg : "";
  const std::string saved_home = std::getenv("HOME") ? std::getenv("HOME") : "";
  ::setenv("XDG_STATE_HOME", "/var/lab/state", 1);
  EXPECT_EQ(*DefaultSpoolDir("arm/1"), fs::path("/var/lab/state/surfmap/spool/arm%2F1"));
  ::setenv("XDG_STATE_HOME", "relative/ignored", 1);
  ::setenv("HOME", "/home/lab", 1);
  EXPECT_EQ(*DefaultSpoolDir("arm"), fs::path("/home/lab/.local/state/surfmap/spool/arm"));
  ::unsetenv("XDG_STATE_HOME");
  ::unsetenv("HOME");
  EXPECT_EQ(DefaultSpoolDir("arm").status().code(), absl::StatusCode::kFailedPrecondition);
  if (old_xdg) ::setenv("XDG_STATE_HOME", saved_xdg.c_str(), 1);
  if (!saved_home.empty()) ::setenv("HOME", saved_home.c_str(), 1);
}

}  // namespace
}  // namespace surfmap::rig
