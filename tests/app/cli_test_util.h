#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli.h"
#include "scratch_dir.h"
#ifdef SYLVA_TESTS_WITH_GRAPHICS
#include "app/graphics.h"
#endif

namespace sylva::app::testing {

struct CliResult {
  int code = -1;
  std::string out, err;
};

inline CliResult RunSylva(std::vector<std::string> args) {
  std::ostringstream out, err;
  CliResult r;
#ifdef SYLVA_TESTS_WITH_GRAPHICS
  r.code = RunCliWithGraphics(args, out, err);
#else
  r.code = RunCli(args, out, err);
#endif
  r.out = out.str();
  r.err = err.str();
  return r;
}

// A scratch folder per test program.
inline std::filesystem::path Scratch() {
  return sylva::testing::ScratchDir("sylva_cli_");
}

inline std::string WriteFile(const std::string& name, const std::string& text) {
  auto p = Scratch() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

inline std::string Source(const std::string& rel) {
  return std::string(SYLVA_SOURCE_DIR) + "/" + rel;
}

}  // namespace sylva::app::testing
