#include "core/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace fs = std::filesystem;

namespace sylva {

static fs::path TempDir() {
  fs::path d = fs::temp_directory_path() / ("sylva_atomic_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

static int CountEntries(const fs::path& d) {
  int n = 0;
  for ([[maybe_unused]] auto& e : fs::directory_iterator(d)) ++n;
  return n;
}

TEST(AtomicFile, CommitWritesWholeFile) {
  fs::path d = TempDir() / "commit";
  fs::create_directories(d);
  std::string path = (d / "out.txt").string();
  AtomicFile f;
  ASSERT_TRUE(f.Open(path).ok());
  ASSERT_TRUE(f.Write("hello ").ok());
  ASSERT_TRUE(f.Write("world").ok());
  ASSERT_TRUE(f.Commit().ok());
  auto text = ReadFile(path);
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(*text, "hello world");
  EXPECT_EQ(CountEntries(d), 1) << "temporary file left behind";
}

TEST(AtomicFile, AbandonedWriteLeavesNothing) {
  fs::path d = TempDir() / "abandon";
  fs::create_directories(d);
  {
    AtomicFile f;
    ASSERT_TRUE(f.Open((d / "out.txt").string()).ok());
    ASSERT_TRUE(f.Write("partial").ok());
  }
  EXPECT_EQ(CountEntries(d), 0);
}

TEST(AtomicFile, KeepsOldFileUntilCommit) {
  fs::path d = TempDir() / "keep";
  fs::create_directories(d);
  std::string path = (d / "out.txt").string();
  {
    AtomicFile f;
    ASSERT_TRUE(f.Open(path).ok());
    ASSERT_TRUE(f.Write("old").ok());
    ASSERT_TRUE(f.Commit().ok());
  }
  {
    AtomicFile f;
    ASSERT_TRUE(f.Open(path).ok());
    ASSERT_TRUE(f.Write("new but abandoned").ok());
  }
  EXPECT_EQ(*ReadFile(path), "old");
}

TEST(AtomicFile, UnwritableFolderIsARuntimeError) {
  AtomicFile f;
  Status s = f.Open("/nonexistent-folder/out.txt");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().kind, ErrorKind::kRuntime);
  EXPECT_NE(s.error().message.find("cannot create"), std::string::npos) << s.error().message;
}

TEST(ReadFile, MissingFileNamesPath) {
  auto r = ReadFile("/no/such/file.lsys");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().loc.file, "/no/such/file.lsys");
}

}  // namespace sylva
