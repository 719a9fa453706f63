#include "core/atomic_file.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <unistd.h>
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

Expected<std::string> ReadFile(const std::string& path) {
  struct stat st;
  if (stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    Diagnostic d;
    d.loc.file = path;
    d.message = "is a directory, not a file";
    return d;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    Diagnostic d;
    d.loc.file = path;
    d.message = std::string("cannot read file: ") + std::strerror(errno);
    return d;
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace sylva
