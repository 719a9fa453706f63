// cpfg's environment files: what answers ?E in a cpfg user's folder.
//
// cpfg is started as `cpfg -e tree.e tree.l tree.v` (the object's
// `specifications` file holds that command line); tree.e names an
// environment program and how to talk to it:
//
//   executable: honda81 -e tree.e density.spec
//   communication type: files
//   turtle position:P:%.4f %.0f %.4f
//
// cpfg runs the program as a separate process and sends it, after each
// step, every ?E module with the turtle state the file asks for; the
// program's answers fill the modules' parameters. Sylva has no such
// processes: it builds in the programs that vlab's objects use (honda81
// and ecosystem: plant/density_environment.h; clover:
// plant/clover_environment.h; chiba: plant/chiba_environment.h) and
// answers ?E the same way, reading the program's own spec file. A program
// Sylva lacks (soil, ecosystemR, MonteCarlo, ...) is a warning at the
// `executable:` line that names it, and ?E keeps its parameters.
//
// The positions go through the file's `turtle position:` format as cpfg's
// file communication would write them (`%.0f` rounds to whole units), and
// a program that needs 3 coordinates answers nothing when the format has
// fewer, as in cpfg.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/diagnostic.h"
#include "plant/environment.h"

namespace sylva::plant {

// Where cpfg's environment file for the grammar at `grammarPath` is: the
// `-e FILE` of the cpfg command line in the folder's `specifications` (or
// `LSspecifications`), else STEM.e beside the grammar when it exists.
// `namedAt` is the line that names it (empty for STEM.e). nullopt: the
// folder names none. `readFile` reads a file's text (empty: the file
// system).
struct CpfgEnvironmentRef {
  std::string file;   // the .e file, resolved against the grammar's folder
  SourceLoc namedAt;  // the specifications line naming it, if any
  std::string namedLine;
  int namedLength = 1;
};
std::optional<CpfgEnvironmentRef> FindCpfgEnvironment(
    const std::string& grammarPath,
    const std::function<std::optional<std::string>(const std::string&)>& readFile);

// The environment the file at `ref` describes, or null when Sylva does not
// have its program (or the file cannot be read): then a warning says so.
// Warnings about the .e and spec files go to `diagnostics`; nothing here is
// an error, since cpfg itself goes on without an environment.
std::unique_ptr<Environment> LoadCpfgEnvironment(
    const CpfgEnvironmentRef& ref,
    const std::function<std::optional<std::string>(const std::string&)>& readFile,
    DiagnosticList& diagnostics);

}  // namespace sylva::plant
