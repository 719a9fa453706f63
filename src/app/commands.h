// Subcommand options and runners, shared by cli.cpp (which declares the
// flags with CLI11) and the files that implement each subcommand.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostic.h"

namespace sylva::app {

// Flags shared by every command that derives a grammar.
struct DeriveFlags {
  std::string file;
  std::optional<int> steps;
  std::optional<uint64_t> seed;
  std::vector<std::string> defines;  // NAME=VALUE
  int threads = 0;
  uint64_t maxModules = 0;  // 0: the library default
};

struct DeriveCommand {
  DeriveFlags derive;
  bool stats = false;
  bool interpret = false;
  std::string output;  // empty: standard output
};

int RunDerive(const DeriveCommand& cmd, std::ostream& out, std::ostream& err);
int RunCheck(const DeriveFlags& flags, std::ostream& out, std::ostream& err);

// Prints diagnostics; returns the exit status they call for (0 when there
// are only warnings).
int Report(const DiagnosticList& list, std::ostream& err);
int Report(const Diagnostic& d, std::ostream& err);

}  // namespace sylva::app
