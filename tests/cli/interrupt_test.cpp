// An interrupted saltus command leaves nothing behind: SIGINT and SIGTERM during `simulate`,
// `render` (with its ffmpeg child) and `run` (with its child saltus) exit 130 / 143 with the
// folder as it was before and no process left running; after a SIGKILL, the next run in the same
// folder removes the stale temporary.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "tests/support/run_saltus.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;
using saltus::testing::runSaltus;

class InterruptTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = saltus::testing::scratchPath("interrupt", ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Starts `saltus ARGS...` in the folder, standard error to a file beside it.
  pid_t start(const std::vector<std::string>& args) {
    std::vector<std::string> all = {SALTUS_BINARY};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    err_ = dir_.string() + ".stderr";
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addchdir_np(&actions, dir_.c_str());
    pid_t pid = 0;
    EXPECT_EQ(::posix_spawn(&pid, SALTUS_BINARY, &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);
    return pid;
  }

  // Waits (up to a minute) until `ready()` holds.
  static bool waitFor(const std::function<bool()>& ready) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      if (ready()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  // Entries of the folder (recursively) inside or named as a temporary (".tmp-"); files that
  // vanish while listed (renamed into place) are skipped.
  std::vector<std::string> temporaries() const {
    std::vector<std::string> found;
    std::error_code error;
    for (fs::recursive_directory_iterator it(dir_, error), end; !error && it != end; it.increment(error)) {
      const std::string path = it->path().string().substr(dir_.string().size());
      if (path.find(".tmp-") != std::string::npos) found.push_back(it->path().string());
    }
    return found;
  }
  std::set<std::string> entries() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
    return names;
  }
  // Processes other than this one whose command line mentions the folder.
  int processesUsingFolder() const {
    int n = 0;
    for (const auto& e : fs::directory_iterator("/proc")) {
      const std::string name = e.path().filename().string();
      if (name.find_first_not_of("0123456789") != std::string::npos) continue;
      std::string cmdline = readFile(e.path() / "cmdline");
      for (char& c : cmdline) c = c == '\0' ? ' ' : c;
      std::string state = readFile(e.path() / "stat");
      const bool zombie = state.find(") Z ") != std::string::npos;
      n += !zombie && std::stoi(name) != ::getpid() && cmdline.find(dir_.string()) != std::string::npos;
    }
    return n;
  }
  // Sends `signal` and returns the exit code (−signal when killed by it).
  static int stop(pid_t pid, int signal) {
    ::kill(pid, signal);
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
  }

  fs::path dir_;
  std::string err_;
};

TEST_F(InterruptTest, SimulateRemovesItsUnfinishedTrajectory) {
  for (const int signal : {SIGINT, SIGTERM}) {
    const pid_t pid = start({"simulate", "ball_drop", "--duration", "100000", "--out", (dir_ / "traj.csv").string(),
                             "--max-output-mb", "1e9"});
    ASSERT_TRUE(waitFor([&] { return !temporaries().empty() && fs::file_size(temporaries()[0]) > 0; }));
    EXPECT_EQ(stop(pid, signal), 128 + signal);
    EXPECT_TRUE(entries().empty()) << *entries().begin();
    EXPECT_NE(readFile(err_).find(signal == SIGINT ? "interrupted by SIGINT" : "interrupted by SIGTERM"),
              std::string::npos)
        << readFile(err_);
  }
}

TEST_F(InterruptTest, AfterAKillTheNextRunRemovesTheStaleTemporary) {
  const pid_t pid = start({"simulate", "ball_drop", "--duration", "100000", "--out", (dir_ / "traj.csv").string(),
                           "--max-output-mb", "1e9"});
  ASSERT_TRUE(waitFor([&] { return !temporaries().empty(); }));
  EXPECT_EQ(stop(pid, SIGKILL), -SIGKILL);
  ASSERT_EQ(temporaries().size(), 1u);  // nothing can clean up after SIGKILL itself
  const auto r = runSaltus({"simulate", "ball_drop", "--duration", "0.1", "--out", (dir_ / "other.csv").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(entries(), (std::set<std::string>{"other.csv"}));
}

TEST_F(InterruptTest, RenderStopsItsEncoderAndRemovesFramesAndVideo) {
  const std::string csv = (dir_ / "p.csv").string();
  ASSERT_EQ(runSaltus({"simulate", "pendulum_conveyor", "--duration", "30", "--out", csv}).status, 0);
  const pid_t pid = start({"render", csv, "--scene", "pendulum_conveyor", "--out", (dir_ / "v.mp4").string(),
                           "--frames", (dir_ / "frames").string(), "--width", "320", "--height", "180"});
  // interrupted once frames are written and the encoder runs
  ASSERT_TRUE(waitFor([&] {
    for (const std::string& t : temporaries())
      if (t.find("frame_00002.png") != std::string::npos) return true;
    return false;
  }));
  EXPECT_EQ(processesUsingFolder(), 2);  // saltus render and its ffmpeg
  EXPECT_EQ(stop(pid, SIGTERM), 143);
  EXPECT_EQ(entries(), (std::set<std::string>{"p.csv"}));
  EXPECT_TRUE(waitFor([&] { return processesUsingFolder() == 0; }));
}

TEST_F(InterruptTest, RunStopsItsChildStep) {
  const pid_t pid = start({"run", "pendulum_conveyor", "--out", (dir_ / "run").string()});
  // interrupted while a step (a child process) runs
  ASSERT_TRUE(waitFor([&] { return processesUsingFolder() >= 2; }));
  EXPECT_EQ(stop(pid, SIGINT), 130);
  EXPECT_EQ(processesUsingFolder(), 0);
  EXPECT_TRUE(temporaries().empty()) << temporaries()[0];
  EXPECT_NE(readFile(err_).find("stopped 1 child process"), std::string::npos) << readFile(err_);
}

}  // namespace
