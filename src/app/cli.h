// The `sylva` command, callable in-process (main.cpp and the tests).
//
// Exit status: 0 success; 1 a run-time failure (a limit reached, an I/O
// error); 2 bad usage or bad input, with GCC-style diagnostics on `err`.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace sylva::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitRuntime = 1;
inline constexpr int kExitBadInput = 2;

int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sylva::app
