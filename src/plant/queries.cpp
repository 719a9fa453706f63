#include "plant/queries.h"

#include <string>

#include "core/assert.h"

namespace sylva::plant {

QueryTable QueryTableOf(const lsys::SymbolTable& symbols) {
  QueryTable t;
  t.bySymbol.assign(symbols.size(), QueryKind::kNone);
  for (size_t s = 0; s < symbols.size(); ++s) {
    const std::string& name = symbols.name(lsys::SymbolId(s));
    const int arity = symbols.arity(lsys::SymbolId(s));
    QueryKind k = QueryKind::kNone;
    if (arity == 2 || arity == 3) {
      if (name == "?P") k = QueryKind::kPosition;
      if (name == "?H") k = QueryKind::kHeading;
      if (name == "?L") k = QueryKind::kLeft;
      if (name == "?U") k = QueryKind::kUp;
    }
    if (name == "?E" && arity >= 1) k = QueryKind::kEnvironment;
    t.bySymbol[s] = k;
    t.any |= k != QueryKind::kNone;
    t.environment |= k == QueryKind::kEnvironment;
  }
  return t;
}

Status CheckQueriesSurviveInterpretation(const lsys::Grammar& g, const QueryTable& table) {
  for (const lsys::Production& p : g.interpretation.productions) {
    bool touches = table.bySymbol[p.pred.symbol] != QueryKind::kNone;
    for (lsys::SymbolId s : p.successor.symbols) touches |= table.bySymbol[s] != QueryKind::kNone;
    if (!touches) continue;
    return MakeError(p.loc,
                     "an interpretation production rewrites or writes a query module (?P ?H ?L "
                     "?U ?E): its answer would have no place in the derived word; keep query "
                     "modules out of the interpretation section",
                     1, g.SourceLine(p.loc));
  }
  return {};
}

namespace {

// Positions of the query modules in a word.
std::vector<uint32_t> QueryIndices(const QueryTable& table, const lsys::Word& w) {
  std::vector<uint32_t> out;
  for (size_t i = 0; i < w.size(); ++i)
    if (table.bySymbol[w.symbols[i]] != QueryKind::kNone) out.push_back(uint32_t(i));
  return out;
}

}  // namespace

Status AnswerQueries(const QueryTable& table, lsys::Word& derived, const lsys::Word& drawn,
                     const mesh::PlantGeometry& geometry, Environment* environment,
                     uint32_t plant) {
  SYLVA_ASSERT(geometry.modulePosition.size() == drawn.size());
  const bool same = &derived == &drawn;
  const std::vector<uint32_t> inDerived = QueryIndices(table, derived);
  const std::vector<uint32_t> inDrawn = same ? inDerived : QueryIndices(table, drawn);
  if (inDerived.size() != inDrawn.size()) {
    Diagnostic d;
    d.message = "the interpretation rules changed the query modules (" +
                std::to_string(inDerived.size()) + " in the derived word, " +
                std::to_string(inDrawn.size()) + " in the word drawn)";
    return d;
  }
  std::vector<EnvQuery> envQueries;
  for (size_t q = 0; q < inDerived.size(); ++q) {
    const uint32_t i = inDerived[q], w = inDrawn[q];
    const lsys::SymbolId sym = derived.symbols[i];
    if (sym != drawn.symbols[w]) {
      Diagnostic d;
      d.message = "the interpretation rules changed query module " + std::to_string(q + 1) +
                  " of the derived word";
      return d;
    }
    double* p = derived.params.data() + derived.paramStart[i];
    const uint32_t n = derived.paramStart[i + 1] - derived.paramStart[i];
    const mesh::Frame& f = geometry.moduleFrame[w];
    const Vec3* v = nullptr;
    switch (table.bySymbol[sym]) {
      case QueryKind::kPosition:
        v = &geometry.modulePosition[w];
        break;
      case QueryKind::kHeading:
        v = &f.heading;
        break;
      case QueryKind::kLeft:
        v = &f.left;
        break;
      case QueryKind::kUp:
        v = &f.up;
        break;
      case QueryKind::kEnvironment:
        // Without an environment (no `environment:`; the parser warned)
        // ?E keeps its values.
        if (environment)
          envQueries.push_back(EnvQuery{geometry.modulePosition[w], f, {p, n}, plant});
        continue;
      case QueryKind::kNone:
        continue;
    }
    for (uint32_t c = 0; c < n && c < 3; ++c) p[c] = (*v)[c];
  }
  if (!envQueries.empty()) {
    if (Status s = environment->Answer(envQueries); !s.ok()) return s;
  }
  return {};
}

}  // namespace sylva::plant
