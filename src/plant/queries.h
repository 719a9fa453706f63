// Answering the query modules of an open L-system between derivation steps
// (cpfg's semantics; Prusinkiewicz, James & Mech, "Synthetic topiary",
// SIGGRAPH 1994; Mech & Prusinkiewicz, SIGGRAPH 1996):
//
//   ?P(x, y[, z])  the turtle's position at the module
//   ?H ?L ?U       its heading, left and up vectors there
//   ?E(...)        what the Environment answers (plant/environment.h)
//
// With 2 parameters a query takes x and y, with 3 x, y and z (other counts
// are warned about by the parser and left alone). The word is drawn through
// the interpretation rules first, so the turtle sees what the picture shows;
// the k-th query module of the derived word is the k-th of the drawn word,
// so interpretation productions must neither rewrite nor make query modules
// (CheckQueriesSurviveInterpretation says so, at the production).
#pragma once

#include <cstdint>
#include <vector>

#include "core/status.h"
#include "lsys/grammar.h"
#include "lsys/word.h"
#include "mesh/plant_geometry.h"
#include "plant/environment.h"

namespace sylva::plant {

enum class QueryKind : uint8_t { kNone, kPosition, kHeading, kLeft, kUp, kEnvironment };

// What each symbol of a grammar asks, by symbol id.
struct QueryTable {
  std::vector<QueryKind> bySymbol;
  bool any = false;          // some symbol is answered
  bool environment = false;  // ?E is among them
};

QueryTable QueryTableOf(const lsys::SymbolTable& symbols);

// An error at the first interpretation production whose predecessor is a
// query module or whose successor writes one.
Status CheckQueriesSurviveInterpretation(const lsys::Grammar& g, const QueryTable& table);

// Fills the query modules of `derived` from `geometry`, the turtle's record
// of `drawn` (DrawOptions::recordModules), and `environment` (may be null
// when table.environment is false). `drawn` is `derived` through the
// interpretation rules, or `derived` itself.
Status AnswerQueries(const QueryTable& table, lsys::Word& derived, const lsys::Word& drawn,
                     const mesh::PlantGeometry& geometry, Environment* environment,
                     uint32_t plant = 0);

}  // namespace sylva::plant
