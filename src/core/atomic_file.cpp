#include "core/atomic_file.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <sys/stat.h>

namespace sylva {

AtomicFile::~AtomicFile() { Abandon(); }

void AtomicFile::Abandon() {
  if (file_) {
    std::fclose(file_);
    file_ = nullptr;
  }
  if (!tmpPath_.empty()) {
    std::remove(tmpPath_.c_str());
    tmpPath_.clear();
  }
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
  std::string tmpl = path + ".tmp-XXXXXX";
  int fd = mkstemp(tmpl.data());
  if (fd < 0) return IoError("cannot create output file");
  tmpPath_ = tmpl;
  fchmod(fd, 0644);
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

Status AtomicFile::Commit() {
  SYLVA_ASSERT(file_ != nullptr);
  bool ok = std::fflush(file_) == 0;
  ok = (std::fclose(file_) == 0) && ok;
  file_ = nullptr;
  if (!ok) {
    Status s = IoError("write failed");
    Abandon();
    return s;
  }
  if (std::rename(tmpPath_.c_str(), path_.c_str()) != 0) {
    Status s = IoError("cannot rename output into place");
    Abandon();
    return s;
  }
  tmpPath_.clear();
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
    return fail("file is larger than the limit of " +
                (maxBytes >= (size_t(1) << 20) ? std::to_string(maxBytes >> 20) + " MiB"
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
