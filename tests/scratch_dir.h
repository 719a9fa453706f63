// A scratch folder for one test program: made on first use under the
// system's temporary folder, named by `prefix` and the process id, and
// removed with everything in it when the program exits.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace sylva::testing {

inline std::filesystem::path ScratchDir(const std::string& prefix) {
  struct Dir {
    std::filesystem::path path;
    explicit Dir(const std::string& p)
        : path(std::filesystem::temp_directory_path() / (p + std::to_string(::getpid()))) {
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static Dir dir(prefix);
  std::filesystem::create_directories(dir.path);
  return dir.path;
}

}  // namespace sylva::testing
