// Output files that appear whole or not at all.
//
// A regular file (or a path that does not exist yet) is written to a
// temporary file beside it and renamed over it on Commit(), so a failed or
// interrupted run never leaves a half-written output and an existing file
// stays untouched until the new one is complete. A writer destroyed without
// Commit() removes its temporary file; so does SIGINT/SIGTERM/SIGHUP once
// InstallTemporaryFileCleanup() has run (the `sylva` command does).
//
// Targets that are not regular files are never replaced:
// - a symbolic link is followed (to the end of its chain) and the file it
//   names is written atomically in its own folder: the link stays a link;
// - a character device or FIFO (/dev/null, /dev/stdout, a named pipe) is
//   written through directly, with no temporary file: there is nothing to
//   replace, and every write and the final flush are still checked;
// - a directory, a socket or a block device is an error.
// New files get mode 0666 less the umask, as any program's; an existing
// file keeps its mode.
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

  // Opens the output for `path` as described above.
  Status Open(const std::string& path);
  Status Write(const void* data, size_t bytes);
  Status Write(std::string_view s) { return Write(s.data(), s.size()); }
  // Flushes and closes the data; the file is not in place yet. Errors of the
  // last writes (a full disk) show here.
  Status Finish();
  // Finish() if not done, then renames onto the target.
  Status Commit();
  FILE* handle() { return file_; }
  // True when writing straight through to a device or FIFO.
  bool direct() const { return direct_; }

 private:
  Status IoError(const std::string& what) const;
  void Abandon();

  std::string path_;     // as the caller named it (for messages)
  std::string target_;   // where the data goes: path_ with links resolved
  std::string tmpPath_;  // empty when writing directly or after Commit
  int slot_ = -1;        // in the signal cleanup registry
  FILE* file_ = nullptr;
  bool finished_ = false, direct_ = false;
};

// Installs SIGINT, SIGTERM and SIGHUP handlers that remove every temporary
// file an AtomicFile has open, then end the process with the signal's
// default action. Call once, early in main().
void InstallTemporaryFileCleanup();

// Reads a whole regular file (a link to one is fine) of at most maxBytes;
// the error names the path. A directory, device, FIFO or socket is an
// error, found without blocking, and so is a file larger than maxBytes.
inline constexpr size_t kDefaultMaxReadBytes = size_t(64) << 20;
Expected<std::string> ReadFile(const std::string& path, size_t maxBytes = kDefaultMaxReadBytes);

}  // namespace sylva
