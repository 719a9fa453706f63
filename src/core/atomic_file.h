// Output files that appear whole or not at all: data is written to a
// temporary file beside the target and renamed over it on Commit(). A writer
// destroyed without Commit() removes its temporary file.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

#include "core/status.h"

namespace sylva {

class AtomicFile {
 public:
  AtomicFile() = default;
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Opens "<path>.tmp-XXXXXX" in the target's folder.
  Status Open(const std::string& path);
  Status Write(const void* data, size_t bytes);
  Status Write(std::string_view s) { return Write(s.data(), s.size()); }
  // Flushes, closes and renames onto the target path.
  Status Commit();
  FILE* handle() { return file_; }

 private:
  Status IoError(const std::string& what) const;
  void Abandon();

  std::string path_, tmpPath_;
  FILE* file_ = nullptr;
};

// Reads a whole regular file (a link to one is fine) of at most maxBytes;
// the error names the path. A directory, device, FIFO or socket is an
// error, found without blocking, and so is a file larger than maxBytes.
inline constexpr size_t kDefaultMaxReadBytes = size_t(64) << 20;
Expected<std::string> ReadFile(const std::string& path, size_t maxBytes = kDefaultMaxReadBytes);

}  // namespace sylva
