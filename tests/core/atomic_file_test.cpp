#include "core/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <sys/stat.h>
#include <unistd.h>

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

namespace sylva {

static Expected<std::string> ReadIn(const fs::path& p, size_t max = kDefaultMaxReadBytes) {
  return ReadFile(p.string(), max);
}

TEST(ReadFile, ReadsRegularFilesAndLinksToThem) {
  fs::path d = TempDir() / "read";
  fs::create_directories(d);
  std::ofstream(d / "a.txt", std::ios::binary) << "hello";
  fs::remove(d / "link.txt");
  fs::create_symlink(d / "a.txt", d / "link.txt");
  auto a = ReadIn(d / "a.txt");
  ASSERT_TRUE(a.ok()) << a.error().Format();
  EXPECT_EQ(*a, "hello");
  auto l = ReadIn(d / "link.txt");
  ASSERT_TRUE(l.ok()) << l.error().Format();
  EXPECT_EQ(*l, "hello");
  // /proc files say they are empty and are not.
  auto proc = ReadIn("/proc/self/status");
  ASSERT_TRUE(proc.ok()) << proc.error().Format();
  EXPECT_GT(proc->size(), 0u);
}

TEST(ReadFile, DevicesFifosAndDirectoriesAreErrorsWithoutBlocking) {
  // /dev/zero used to end in bad_alloc and a FIFO blocked in open().
  fs::path d = TempDir() / "special";
  fs::create_directories(d);
  fs::path fifo = d / "fifo";
  fs::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  fs::remove(d / "to_zero");
  fs::create_symlink("/dev/zero", d / "to_zero");
  for (const fs::path& p : {fs::path("/dev/zero"), fifo, d / "to_zero"}) {
    auto r = ReadIn(p);
    ASSERT_FALSE(r.ok()) << p;
    EXPECT_EQ(r.error().message, "is not a regular file (a device, FIFO or socket)") << p;
    EXPECT_EQ(r.error().loc.file, p.string());
  }
  auto dir = ReadIn(d);
  ASSERT_FALSE(dir.ok());
  EXPECT_EQ(dir.error().message, "is a directory, not a file");
  auto missing = ReadIn(d / "missing");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("No such file"), std::string::npos)
      << missing.error().message;
}

TEST(ReadFile, FilesLargerThanTheLimitAreErrors) {
  fs::path d = TempDir() / "limit";
  fs::create_directories(d);
  std::ofstream(d / "ten.txt", std::ios::binary) << "0123456789";
  auto ok = ReadIn(d / "ten.txt", 10);
  ASSERT_TRUE(ok.ok()) << ok.error().Format();
  EXPECT_EQ(ok->size(), 10u);
  auto big = ReadIn(d / "ten.txt", 9);
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.error().message, "file is larger than the limit of 9 bytes");
  // A file that reports size 0 is still cut at the limit.
  auto proc = ReadIn("/proc/self/maps", 16);
  ASSERT_FALSE(proc.ok());
  EXPECT_EQ(proc.error().message, "file is larger than the limit of 16 bytes");
}

}  // namespace sylva
