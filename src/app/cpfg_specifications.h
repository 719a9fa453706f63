// The cpfg command of a vlab object's `specifications` file.
//
// vlab keeps each object's files in one folder, with a `specifications`
// file whose menu items run commands; the one that draws the plant is a
// cpfg command line such as
//
//     generate:
//         cpfg -M materials.mat -e plant.e lamp.l view.v anim.a
//
// cpfg takes every file from that line (vlab cpfg/main.c, ParseCommand):
// the first file name is the L-system, the second the view file, the third
// the animation file; `-m[n] FILE` a colour map (n = 1 without a digit),
// `-M[n] FILE` a material file (the later of -m and -M wins), `-e FILE` the
// environment. So the view file need not be named after the `.l` (`view.v`,
// `viewfile.v`). ReadCpfgCommands returns every cpfg line of a
// specifications file; CpfgCommandFor the one whose L-system is a given
// `.l`. The view file reader (view_file.h) and the environment and function
// readers use it when NAME.v is not beside the grammar.
//
// A specifications file is a few kilobytes; one over 1 MiB, or one that is
// not a regular file, is not read (an error the caller reports), and at most
// 4096 cpfg lines of at most 64 words each are kept.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "core/status.h"

namespace sylva::app {

struct CpfgCommand {
  SourceLoc loc;              // the specifications file, line and column of `cpfg`
  std::string lsystem;        // the first file name (the .l)
  std::string view;           // the second (the .v); empty when there is none
  std::string animation;      // the third (the .a); empty when there is none
  std::string colormap;       // -m FILE or -m1 FILE (else the lowest -mN)
  std::string material;       // -M FILE or -M1 FILE (else the lowest -MN)
  bool materialWins = false;  // -M came after the last -m (cpfg: the later wins)
  std::string environment;    // -e FILE
  // Options cpfg does not have (cpfg itself stops with its usage message).
  std::vector<std::string> unknownOptions;
};

// Every cpfg command of the specifications text (`path` names it in
// locations). A command is a word `cpfg` (or `cpfg` and a version, `cpfg3.2`)
// at the start of a line or after a `;`; its words run to the end of the
// line or the next `;`. File names are as written (relative to the
// object's folder).
std::vector<CpfgCommand> ParseCpfgCommands(const std::string& text, const std::string& path);

// Reads `specifications` in the folder of `grammarPath` and returns the
// first cpfg command whose L-system is that grammar's file name; nullopt
// when there is no such file or command. An error when the file exists
// but cannot be read (not a regular file, over 1 MiB).
Expected<std::optional<CpfgCommand>> CpfgCommandFor(const std::string& grammarPath);

}  // namespace sylva::app
