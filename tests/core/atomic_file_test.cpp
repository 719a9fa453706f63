#include "core/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include <sys/stat.h>
#include <unistd.h>
#include "scratch_dir.h"

namespace fs = std::filesystem;

namespace sylva {

static fs::path TempDir() {
  return sylva::testing::ScratchDir("sylva_atomic_");
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

namespace sylva {

static std::string Slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

TEST(AtomicFile, SymlinkTargetStaysALinkAndItsFileGetsTheData) {
  fs::path d = TempDir() / "symlink";
  fs::remove_all(d);
  fs::create_directories(d / "real");
  std::ofstream(d / "real" / "data.txt") << "old";
  fs::create_symlink("real/data.txt", d / "link.txt");
  AtomicFile f;
  ASSERT_TRUE(f.Open((d / "link.txt").string()).ok());
  ASSERT_TRUE(f.Write("new").ok());
  ASSERT_TRUE(f.Commit().ok());
  EXPECT_TRUE(fs::is_symlink(d / "link.txt")) << "the link was replaced by a file";
  EXPECT_EQ(Slurp(d / "real" / "data.txt"), "new");
  EXPECT_EQ(CountEntries(d / "real"), 1) << "temporary file left beside the link's target";
  // A dangling link names the file to create.
  fs::create_symlink("real/fresh.txt", d / "dangling.txt");
  ASSERT_TRUE(f.Open((d / "dangling.txt").string()).ok());
  ASSERT_TRUE(f.Write("made").ok());
  ASSERT_TRUE(f.Commit().ok());
  EXPECT_TRUE(fs::is_symlink(d / "dangling.txt"));
  EXPECT_EQ(Slurp(d / "real" / "fresh.txt"), "made");
}

TEST(AtomicFile, FifoIsWrittenThroughNeverReplaced) {
  fs::path d = TempDir() / "fifo";
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string fifo = (d / "pipe").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = Slurp(fifo); });
  AtomicFile f;
  ASSERT_TRUE(f.Open(fifo).ok());
  EXPECT_TRUE(f.direct());
  ASSERT_TRUE(f.Write("through the pipe").ok());
  ASSERT_TRUE(f.Commit().ok());
  reader.join();
  EXPECT_EQ(got, "through the pipe");
  struct stat st;
  ASSERT_EQ(lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the FIFO was replaced; mode " << std::oct << st.st_mode;
  EXPECT_EQ(CountEntries(d), 1);
}

TEST(AtomicFile, DeviceIsWrittenThroughAndAFullDeviceIsAnError) {
  // /dev/null stays a character device; /dev/full fails at the flush.
  AtomicFile f;
  ASSERT_TRUE(f.Open("/dev/null").ok());
  ASSERT_TRUE(f.Write("discarded").ok());
  ASSERT_TRUE(f.Commit().ok());
  struct stat st;
  ASSERT_EQ(stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "mode " << std::oct << st.st_mode;
  if (access("/dev/full", W_OK) == 0) {
    ASSERT_TRUE(f.Open("/dev/full").ok());
    (void)f.Write("no room");
    Status s = f.Commit();
    ASSERT_FALSE(s.ok()) << "a write to /dev/full reported success";
    EXPECT_EQ(s.error().kind, ErrorKind::kRuntime);
  }
}

TEST(AtomicFile, DirectoryTargetIsAnErrorAndStaysADirectory) {
  fs::path d = TempDir() / "dir_target";
  fs::create_directories(d);
  AtomicFile f;
  Status s = f.Open(d.string());
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("directory"), std::string::npos) << s.error().message;
  EXPECT_TRUE(fs::is_directory(d));
}

TEST(AtomicFile, NewFilesHonourTheUmaskAndExistingFilesKeepTheirMode) {
  fs::path d = TempDir() / "modes";
  fs::remove_all(d);
  fs::create_directories(d);
  const mode_t old = umask(027);
  AtomicFile f;
  ASSERT_TRUE(f.Open((d / "new.txt").string()).ok());
  ASSERT_TRUE(f.Commit().ok());
  umask(old);
  struct stat st;
  ASSERT_EQ(stat((d / "new.txt").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u) << "mode " << std::oct << (st.st_mode & 0777);
  ASSERT_EQ(chmod((d / "new.txt").c_str(), 0600), 0);
  ASSERT_TRUE(f.Open((d / "new.txt").string()).ok());
  ASSERT_TRUE(f.Write("again").ok());
  ASSERT_TRUE(f.Commit().ok());
  ASSERT_EQ(stat((d / "new.txt").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u) << "mode " << std::oct << (st.st_mode & 0777);
}

TEST(AtomicFile, NameTooLongIsAnErrorNotAnException) {
  AtomicFile f;
  Status s = f.Open((TempDir() / std::string(300, 'x')).string() + ".txt");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("too long"), std::string::npos) << s.error().message;
}

}  // namespace sylva
