// scene/cleanup.hpp: stale temporaries of dead processes are removed and nothing else is; a
// registered temporary goes with its owner; children run in a process group of their own with
// the default signal dispositions. (The interrupt itself is tested on the saltus program, in
// tests/cli/interrupt_test.cpp.)
#include "scene/cleanup.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <fcntl.h>

#include <gtest/gtest.h>

#include "scene/atomic_file.hpp"

namespace saltus::scene {
namespace {

namespace fs = std::filesystem;

class CleanupTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("saltus_cleanup_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void touch(const std::string& name) const { std::ofstream(dir_ / name) << "x"; }
  std::set<std::string> entries() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
    return names;
  }
  fs::path dir_;
};

// The pid of a process that has ended (forked, exited and reaped).
pid_t deadPid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return pid;
}

std::string host() {
  char name[256] = {};
  ::gethostname(name, sizeof name - 1);
  return name;
}

TEST_F(CleanupTest, RemovesOnlyTheTemporariesOfDeadProcessesOnThisMachine) {
  const std::string dead = std::to_string(deadPid());
  const std::string alive = std::to_string(::getppid());  // the process that started the test
  touch("a.csv.tmp-" + dead + "@" + host());                // a killed simulate
  touch("v.mp4.tmp-" + dead + "@" + host() + ".mp4");       // a killed encoder's video
  touch("v.mp4.tmp-" + dead + "@" + host() + ".ffmpeg.log");
  touch("c.png.tmp-" + dead);                               // older name, no host
  fs::create_directories(dir_ / ("frames.tmp-" + dead + "@" + host()));  // a killed render's frames
  touch("frames.tmp-" + dead + "@" + host() + "/frame_00000.png");
  // kept: a live process's, another machine's (shared file system), this process's, not ours
  const std::set<std::string> kept = {"b.csv.tmp-" + alive + "@" + host(), "d.csv.tmp-" + dead + "@elsewhere-node",
                                      "e.csv.tmp-" + std::to_string(::getpid()) + "@" + host(),
                                      "notes.tmp-abc", "f.tmp-12x", ".tmp-" + dead, "results.csv"};
  for (const std::string& name : kept) touch(name);

  const auto removed = removeStaleTemporaries(dir_.string());
  EXPECT_EQ(removed.size(), 5u);
  EXPECT_EQ(entries(), kept);
  EXPECT_TRUE(removeStaleTemporaries(dir_.string()).empty());  // once per folder and process
}

TEST_F(CleanupTest, TemporaryNamesSayTheProcessAndMachine) {
  const std::string name = temporaryName((dir_ / "out.csv").string(), ".mp4");
  EXPECT_EQ(name, (dir_ / "out.csv").string() + ".tmp-" + std::to_string(::getpid()) + "@" + host() + ".mp4");
  AtomicFile file((dir_ / "out.csv").string());
  EXPECT_EQ(file.temporaryPath(), temporaryName((dir_ / "out.csv").string()));
}

TEST_F(CleanupTest, AScopedTemporaryIsRemovedUnlessKept) {
  {
    ScopedTemporary folder((dir_ / "scratch").string());
    fs::create_directories(dir_ / "scratch" / "deeper");
    touch("scratch/deeper/x");
  }
  EXPECT_FALSE(fs::exists(dir_ / "scratch"));
  {
    ScopedTemporary file((dir_ / "kept").string());
    touch("kept");
    file.keep();
  }
  EXPECT_TRUE(fs::exists(dir_ / "kept"));
}

TEST_F(CleanupTest, AChildLeadsItsOwnProcessGroupWithDefaultSignals) {
  ::signal(SIGPIPE, SIG_IGN);  // as the encoder's writer sets it
  const fs::path out = dir_ / "status";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  // the child reports its process group and its ignored-signal mask, then exits 3
  const pid_t pid = spawnChild("/bin/sh", {"sh", "-c", "ps -o pgid= -p $$; grep SigIgn /proc/$$/status; exit 3"}, {},
                               &actions);
  posix_spawn_file_actions_destroy(&actions);
  const int status = waitChild(pid);
  ::signal(SIGPIPE, SIG_DFL);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 3);
  std::ifstream in(out);
  long group = 0;
  std::string label, mask;
  in >> group >> label >> mask;
  EXPECT_EQ(group, pid);
  const unsigned long ignored = std::stoul(mask, nullptr, 16);
  EXPECT_EQ(ignored & (1ul << (SIGPIPE - 1)), 0u) << mask;
  EXPECT_EQ(ignored & (1ul << (SIGINT - 1)), 0u) << mask;
}

// An interrupt stops a ChildStop::Kill child at once, even one that ignores SIGTERM (ffmpeg
// reading frames from a pipe waits for the rest of them), and exits 143; a Terminate child that
// ignores SIGTERM would hold the exit up by the 3 s grace time.
TEST_F(CleanupTest, AnInterruptKillsAKillChildAtOnce) {
  const fs::path pid_file = dir_ / "grandchild";
  const auto start = std::chrono::steady_clock::now();
  const pid_t process = ::fork();
  if (process == 0) {
    ::alarm(10);  // a cleanup that never ends fails the test, not hangs it
    installInterruptCleanup("cleanup_test");
    const pid_t child = spawnChild("/bin/sh", {"sh", "-c", "trap '' TERM; while :; do sleep 1; done"}, {}, nullptr,
                                   ChildStop::Kill);
    std::ofstream(pid_file) << child;
    ::raise(SIGTERM);
    for (;;) ::pause();
  }
  int status = 0;
  ASSERT_EQ(::waitpid(process, &status, 0), process);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM);
  EXPECT_LT(seconds, 2.0);  // not the 3 s grace of a Terminate child
  pid_t child = 0;
  std::ifstream(pid_file) >> child;
  ASSERT_GT(child, 0);
  EXPECT_EQ(::kill(child, 0), -1);  // gone (reaped by the cleanup)
  EXPECT_EQ(errno, ESRCH);
}

TEST_F(CleanupTest, AProgramThatCannotStartIsNamed) {
  try {
    spawnChild((dir_ / "missing-program").string(), {"missing-program"}, {}, nullptr);
    FAIL() << "started";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing-program"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace saltus::scene
