// scene/atomic_file.hpp: the target appears whole or not at all, and only a regular file is replaced.
#include "scene/atomic_file.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <sys/stat.h>

#include <gtest/gtest.h>
#include <unistd.h>

#include "tests/support/files.hpp"

namespace saltus::scene {
namespace {

namespace fs = std::filesystem;
using saltus::testing::readFile;

// A fresh folder per test, removed afterwards.
class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("saltus_atomic_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // The folder's entries other than `keep`.
  int strayFiles(const std::string& keep) const {
    int n = 0;
    for (const auto& e : fs::directory_iterator(dir_)) n += e.path().filename() != keep;
    return n;
  }
  fs::path dir_;
};

TEST_F(AtomicFileTest, WritesTheWholeTextAndLeavesNoTemporary) {
  const fs::path target = dir_ / "out.txt";
  writeFileAtomically(target.string(), "first\n");
  writeFileAtomically(target.string(), "second, longer\n");  // replaces a regular file
  EXPECT_EQ(readFile(target), "second, longer\n");
  EXPECT_EQ(strayFiles("out.txt"), 0);
}

TEST_F(AtomicFileTest, AnUncommittedFileLeavesTheTargetAsItWas) {
  const fs::path target = dir_ / "out.txt";
  writeFileAtomically(target.string(), "old\n");
  {
    AtomicFile file(target.string());
    std::fputs("new, interrupted", file.stream());
    EXPECT_TRUE(fs::exists(file.temporaryPath()));
    EXPECT_EQ(fs::path(file.temporaryPath()).parent_path(), target.parent_path());  // same file system
  }  // destroyed before commit(), as by an exception
  EXPECT_EQ(readFile(target), "old\n");
  EXPECT_EQ(strayFiles("out.txt"), 0);
}

TEST_F(AtomicFileTest, RefusesToReplaceWhatIsNotARegularFile) {
  const fs::path real = dir_ / "real.txt", link = dir_ / "link.txt", folder = dir_ / "folder";
  writeFileAtomically(real.string(), "kept\n");
  fs::create_symlink(real, link);
  fs::create_directory(folder);
  for (const fs::path& target : {link, folder}) {
    try {
      AtomicFile file(target.string());
      ADD_FAILURE() << target << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(target.string() + ": exists and is not a regular file"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(readFile(real), "kept\n");
  EXPECT_TRUE(fs::is_directory(folder));
}

TEST_F(AtomicFileTest, ADeviceOrAPipeIsWrittenIntoNotReplaced) {
  // /dev/null (and, through a symlink to it, as /dev/stdout is) stays the character device
  const fs::path link = dir_ / "null";
  fs::create_symlink("/dev/null", link);
  for (const fs::path& target : {fs::path("/dev/null"), link}) {
    writeFileAtomically(target.string(), "discarded\n");
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
  }
  EXPECT_TRUE(fs::is_symlink(link));
  // a pipe: the reader gets the text
  const fs::path fifo = dir_ / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = readFile(fifo); });
  writeFileAtomically(fifo.string(), "through the pipe\n");
  reader.join();
  EXPECT_EQ(got, "through the pipe\n");
  EXPECT_TRUE(fs::is_fifo(fifo));
  // an encoder's output cannot go to a device: refused
  EXPECT_THROW(AtomicFile("/dev/null", AtomicFile::Mode::External, ".mp4"), std::runtime_error);
}

TEST_F(AtomicFileTest, AFileWrittenByAnotherProgramIsRenamedOnCommit) {
  const fs::path target = dir_ / "video.mp4";
  AtomicFile file(target.string(), AtomicFile::Mode::External, ".mp4");
  EXPECT_EQ(file.stream(), nullptr);
  EXPECT_EQ(fs::path(file.temporaryPath()).extension(), ".mp4");
  std::ofstream(file.temporaryPath()) << "encoded";  // as the encoder would
  EXPECT_FALSE(fs::exists(target));
  file.commit();
  EXPECT_EQ(readFile(target), "encoded");
  EXPECT_EQ(strayFiles("video.mp4"), 0);
}

TEST_F(AtomicFileTest, AMissingFolderIsAnErrorNamingTheTarget) {
  const fs::path target = dir_ / "no_such_folder" / "out.txt";
  try {
    writeFileAtomically(target.string(), "x");
    ADD_FAILURE() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(target.string() + ": cannot write"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace saltus::scene
