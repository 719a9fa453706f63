// Subcommand options and runners, shared by cli.cpp (which declares the
// flags with CLI11) and the files that implement each subcommand.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "lsys/deriver.h"
#include "lsys/grammar.h"

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

struct MeshCommand {
  DeriveFlags derive;
  std::string output;  // .obj .ply .glb .gltf
  int sides = 8;
};

int RunDerive(const DeriveCommand& cmd, std::ostream& out, std::ostream& err);
int RunMesh(const MeshCommand& cmd, std::ostream& out, std::ostream& err);

// Parses the grammar named by the flags (with -D), printing diagnostics.
// Returns the grammar, or nullopt with the exit status in *exit.
std::optional<lsys::Grammar> LoadGrammar(const DeriveFlags& f, std::ostream& err, int* exit);
lsys::DeriveOptions DeriveOptionsFrom(const DeriveFlags& f);
int RunCheck(const DeriveFlags& flags, std::ostream& out, std::ostream& err);

// Prints diagnostics; returns the exit status they call for (0 when there
// are only warnings).
int Report(const DiagnosticList& list, std::ostream& err);
int Report(const Diagnostic& d, std::ostream& err);

}  // namespace sylva::app
