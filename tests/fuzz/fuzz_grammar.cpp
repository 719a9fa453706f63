// libFuzzer target: any bytes as a grammar file, parsed, checked, derived
// (bounded), interpreted and printed. Must never crash, hang or leak.
#include <cstddef>
#include <cstdint>
#include <string>

#include "lsys/deriver.h"
#include "lsys/parser.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sylva::lsys;
  std::string text(reinterpret_cast<const char*>(data), size);
  ParseOptions opt;
  // #include sees only the file itself (exercises recursion detection).
  opt.readFile = [&](const std::string& path) -> std::optional<std::string> {
    if (path == "fuzz.lsys") return text;
    return std::nullopt;
  };
  ParseResult r = ParseGrammarText(text, "fuzz.lsys", opt);
  for (const auto& d : r.diagnostics.items) (void)d.Format();
  if (!r.grammar) return 0;
  DeriveOptions d;
  d.threads = 1;
  d.maxModules = 20000;
  d.steps = r.grammar->derivationLength < 12 ? r.grammar->derivationLength : 12;
  auto result = Derive(*r.grammar, d);
  if (!result) {
    (void)result.error().Format();
    return 0;
  }
  auto w = Interpret(*r.grammar, result->word, d);
  if (w) (void)FormatWord(*w, r.grammar->symbols);
  return 0;
}
