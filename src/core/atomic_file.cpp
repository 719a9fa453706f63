#include "core/atomic_file.h"

#include <signal.h>

#include <fcntl.h>
#include <unistd.h>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <ctime>

#include <sys/stat.h>
#include <algorithm>
#include <cstdint>

namespace sylva {

namespace {

// Temporary files open now, for the signal handler: fixed slots of fixed
// size. A slot is 0 (free), 1 (claimed, path being copied) or 2 (published);
// the handler only reads published paths and calls unlink, which is
// async-signal-safe.
constexpr int kSlots = 64;
constexpr size_t kSlotBytes = 4096;
std::atomic<int> slotState[kSlots];
char slotPath[kSlots][kSlotBytes];

int Register(const std::string& path) {
  if (path.size() >= kSlotBytes) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (!slotState[i].compare_exchange_strong(expected, 1)) continue;
    std::memcpy(slotPath[i], path.c_str(), path.size() + 1);
    slotState[i].store(2, std::memory_order_release);
    return i;
  }
  return -1;  // more than kSlots at once: still removed by the destructor
}

void Unregister(int slot) {
  if (slot >= 0) slotState[slot].store(0, std::memory_order_release);
}

void OnSignal(int sig) {
  for (int i = 0; i < kSlots; ++i) {
    if (slotState[i].load(std::memory_order_acquire) == 2) unlink(slotPath[i]);
  }
  signal(sig, SIG_DFL);
  raise(sig);
}

std::string DirName(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

// Follows a chain of symbolic links from `path` to the path they end at
// (which may not exist yet: a dangling link names the file to create).
// Fails on a loop.
bool ResolveLinks(std::string path, std::string* out) {
  for (int hop = 0; hop < 40; ++hop) {
    struct stat st;
    if (lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) {
      *out = path;
      return true;
    }
    std::string target(size_t(st.st_size > 0 ? st.st_size : 4096) + 1, '\0');
    const ssize_t n = readlink(path.c_str(), target.data(), target.size());
    if (n < 0) return false;
    target.resize(size_t(n));
    path = (!target.empty() && target[0] == '/') ? target : DirName(path) + "/" + target;
  }
  errno = ELOOP;
  return false;
}

}  // namespace

void InstallTemporaryFileCleanup() {
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = OnSignal;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &sa, nullptr);
}

AtomicFile::~AtomicFile() {
  Abandon();
}

void AtomicFile::Abandon() {
  if (file_) {
    std::fclose(file_);
    file_ = nullptr;
  }
  if (!tmpPath_.empty()) {
    std::remove(tmpPath_.c_str());
    tmpPath_.clear();
  }
  Unregister(slot_);
  slot_ = -1;
  finished_ = false;
}

Status AtomicFile::IoError(const std::string& what) const {
  Diagnostic d;
  d.loc.file = path_;
  d.kind = ErrorKind::kRuntime;
  d.message = what + ": " + std::strerror(errno);
  return d;
}

Status AtomicFile::Open(const std::string& path) {
  Abandon();
  path_ = path;
  direct_ = false;
  auto fail = [&](const std::string& message) {
    Diagnostic d;
    d.loc.file = path_;
    d.kind = ErrorKind::kRuntime;
    d.message = message;
    return Status(d);
  };
  if (path.empty()) return fail("empty output file name");
  if (path.find('\0') != std::string::npos) return fail("output file name contains a NUL byte");
  struct stat st;
  const bool exists = stat(path.c_str(), &st) == 0;
  if (!exists && errno != ENOENT) return IoError("cannot write output file");
  if (exists && S_ISDIR(st.st_mode)) return fail("is a directory, not a file");
  if (exists && !S_ISREG(st.st_mode)) {
    if (!S_ISCHR(st.st_mode) && !S_ISFIFO(st.st_mode)) {
      return fail("is not a regular file, a character device or a FIFO; refusing to write it");
    }
    // A device or FIFO: write through, never replace it.
    const int fd = open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) return IoError("cannot open output");
    file_ = fdopen(fd, "wb");
    if (!file_) {
      close(fd);
      return IoError("cannot open output");
    }
    direct_ = true;
    target_ = path;
    return {};
  }
  if (!ResolveLinks(path, &target_)) return IoError("cannot follow the symbolic link");
  // A fresh name beside the target: O_EXCL, so the kernel applies the umask
  // to 0666 as for any new file.
  static std::atomic<uint64_t> counter{0};
  const uint64_t salt = (uint64_t(getpid()) << 32) ^ uint64_t(time(nullptr)) ^
                        (counter.fetch_add(1) * 0x9E3779B97F4A7C15ull);
  int fd = -1;
  for (uint64_t attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    char suffix[32];
    std::snprintf(
        suffix, sizeof suffix, ".tmp-%06llx",
        static_cast<unsigned long long>((salt + attempt * 0x2545F4914F6CDD1Dull) & 0xFFFFFF));
    tmpPath_ = target_ + suffix;
    // Registered before it exists: a signal between the two finds at worst
    // a name with no file, never a file it does not know.
    slot_ = Register(tmpPath_);
    fd = open(tmpPath_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
      const int saved = errno;
      Unregister(slot_);
      slot_ = -1;
      errno = saved;
      if (errno != EEXIST) break;
    }
  }
  if (fd < 0) {
    Status s = IoError("cannot create output file");
    tmpPath_.clear();
    return s;
  }
  if (exists) fchmod(fd, st.st_mode & 07777);  // an existing file keeps its mode
  file_ = fdopen(fd, "wb");
  if (!file_) {
    close(fd);
    Status s = IoError("cannot open output file");
    Abandon();
    return s;
  }
  static constexpr size_t kBuffer = 1 << 20;
  std::setvbuf(file_, nullptr, _IOFBF, kBuffer);
  return {};
}

Status AtomicFile::Write(const void* data, size_t bytes) {
  SYLVA_ASSERT(file_ != nullptr);
  if (bytes && std::fwrite(data, 1, bytes, file_) != bytes) {
    Status s = IoError("write failed");
    Abandon();
    return s;
  }
  return {};
}

Status AtomicFile::Finish() {
  if (finished_) return {};
  SYLVA_ASSERT(file_ != nullptr);
  bool ok = std::fflush(file_) == 0;
  ok = (std::fclose(file_) == 0) && ok;
  file_ = nullptr;
  if (!ok) {
    Status s = IoError("write failed");
    Abandon();
    return s;
  }
  finished_ = true;
  return {};
}

Status AtomicFile::Commit() {
  if (Status s = Finish(); !s.ok()) return s;
  if (!direct_ && std::rename(tmpPath_.c_str(), target_.c_str()) != 0) {
    Status s = IoError("cannot rename output into place");
    Abandon();
    return s;
  }
  tmpPath_.clear();
  Abandon();  // releases the cleanup slot; nothing left to remove
  return {};
}

Expected<std::string> ReadFile(const std::string& path, size_t maxBytes) {
  auto fail = [&](std::string message) {
    Diagnostic d;
    d.loc.file = path;
    d.message = std::move(message);
    return d;
  };
  if (path.find('\0') != std::string::npos) return fail("file name contains a NUL byte");
  // O_NONBLOCK: opening a FIFO must not wait for a writer; the type is
  // checked on the open file, so a link to a regular file is fine.
  const int fd = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return fail(std::string("cannot read file: ") + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { close(fd); }
  } closer{fd};
  struct stat st;
  if (fstat(fd, &st) != 0) return fail(std::string("cannot read file: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) return fail("is a directory, not a file");
  if (!S_ISREG(st.st_mode)) return fail("is not a regular file (a device, FIFO or socket)");
  auto tooLarge = [&] {
    return fail("file is larger than the limit of " + (maxBytes >= (size_t(1) << 20)
                                                           ? std::to_string(maxBytes >> 20) + " MiB"
                                                           : std::to_string(maxBytes) + " bytes"));
  };
  if (st.st_size > 0 && uint64_t(st.st_size) > maxBytes) return tooLarge();
  // Read to the end: the size fstat gives can be stale (a growing file) or 0 (/proc).
  std::string text;
  text.resize(std::min<size_t>(size_t(st.st_size), maxBytes) + 1);
  size_t used = 0;
  for (;;) {
    if (used == text.size()) {
      if (used > maxBytes) return tooLarge();
      text.resize(std::min(maxBytes + 1, used * 2 + 4096));
    }
    const ssize_t n = read(fd, text.data() + used, text.size() - used);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail(std::string("cannot read file: ") + std::strerror(errno));
    }
    if (n == 0) break;
    used += size_t(n);
  }
  if (used > maxBytes) return tooLarge();
  text.resize(used);
  return text;
}

}  // namespace sylva
