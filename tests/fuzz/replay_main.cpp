// A plain driver for the fuzz targets, without libFuzzer: runs
// LLVMFuzzerTestOneInput once on each file named, and on each file of each
// folder named (in name order). Linked with a target's source into the
// normal build, it replays tests/fuzz/regressions/TARGET/ as a ctest; under
// scripts/sanitize.sh the same test runs with ASan and UBSan. A finding
// crashes (a sanitizer report or the target's abort); exit 0 otherwise,
// exit 2 when nothing could be read.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

bool Replay(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const std::string input = bytes.str();
  std::fprintf(stderr, "replay %s (%zu bytes)\n", file.string().c_str(), input.size());
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(input.data()), input.size());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  int replayed = 0;
  for (int a = 1; a < argc; ++a) {
    const std::filesystem::path arg(argv[a]);
    std::error_code ec;
    if (!std::filesystem::is_directory(arg, ec)) {
      if (!Replay(arg)) {
        std::fprintf(stderr, "%s: cannot read\n", argv[a]);
        return 2;
      }
      ++replayed;
      continue;
    }
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(arg, ec)) {
      if (e.is_regular_file()) files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      if (!Replay(f)) {
        std::fprintf(stderr, "%s: cannot read\n", f.string().c_str());
        return 2;
      }
      ++replayed;
    }
  }
  std::fprintf(stderr, "%d inputs replayed, no finding\n", replayed);
  return replayed > 0 ? 0 : 2;
}
