// Helpers for lsys tests: parse a grammar from text, derive it, print words.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "lsys/deriver.h"
#include "lsys/parser.h"

namespace sylva::lsys::testing {

inline Grammar MustParse(const std::string& text, const ParseOptions& opt = {}) {
  ParseResult r = ParseGrammarText(text, "test.lsys", opt);
  if (!r.grammar) {
    ADD_FAILURE() << "grammar did not parse:\n" << r.diagnostics.FormatAll() << "\n" << text;
    return Grammar{};
  }
  return std::move(*r.grammar);
}

// "line:col message" of every diagnostic of a parse, in order.
inline std::vector<std::string> DiagnosticLines(const ParseResult& r) {
  std::vector<std::string> out;
  for (const auto& d : r.diagnostics.items)
    out.push_back(std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " +
                  d.message);
  return out;
}

// Lines joined for a failure message.
inline std::string Joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}

inline DeriveResult MustDerive(const Grammar& g, DeriveOptions opt = {}) {
  auto r = Derive(g, opt);
  if (!r) {
    ADD_FAILURE() << "derivation failed: " << r.error().Format();
    return DeriveResult{};
  }
  return std::move(r).value();
}

// The canonical text of the word derived from `text` in `steps` steps.
inline std::string DeriveText(const std::string& text, int steps = -1, DeriveOptions opt = {}) {
  Grammar g = MustParse(text);
  if (g.main.bySymbol.size() != g.symbols.size()) return "<grammar did not parse>";
  opt.steps = steps;
  return FormatWord(MustDerive(g, opt).word, g.symbols);
}

inline std::string SourcePath(const std::string& rel) {
  return std::string(SYLVA_SOURCE_DIR) + "/" + rel;
}

// The first error of parsing `text` (as the file `path`) as
// "line:column message", or "<no error>".
inline std::string FirstError(const std::string& text, const std::string& path = "c.l") {
  ParseResult r = ParseGrammarText(text, path);
  for (const auto& d : r.diagnostics.items) {
    if (d.severity == Severity::kError)
      return std::to_string(d.loc.line) + ":" + std::to_string(d.loc.column) + " " + d.message;
  }
  return "<no error>";
}

}  // namespace sylva::lsys::testing
