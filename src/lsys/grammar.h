// Grammar: a parsed and checked L-system, ready to derive.
//
// Productions are grouped per section (main, decomposition, interpretation)
// and indexed by predecessor symbol, so choosing a production for a module
// looks only at the productions of its own symbol, in file order.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/diagnostic.h"
#include "lsys/array_bounds.h"
#include "lsys/cpfg_curve.h"
#include "lsys/cpfg_data_files.h"
#include "lsys/cpfg_function.h"
#include "lsys/expr.h"
#include "lsys/expr_parser.h"
#include "lsys/symbols.h"
#include "lsys/word.h"

namespace sylva::lsys {

// A module with formal parameters, as in a predecessor or a context.
// Its parameters bind formal slots [firstFormal, firstFormal + arity).
struct FormalModule {
  SymbolId symbol = 0;
  uint16_t firstFormal = 0;
};

// A successor word: its modules and one Expr per parameter, in order.
struct Successor {
  std::vector<SymbolId> symbols;
  std::vector<Expr> params;
  bool allConstant = true;  // every parameter is a constant
  // cpfg statement blocks written in the successor (`B(y) {z = y+1;} C(z)`):
  // each runs before the module at `before` is written (symbols.size():
  // after the last one).
  struct Block {
    uint32_t before = 0;
    Expr code;
  };
  std::vector<Block> blocks;
};

// cpfg's `=` in a right context (`A > [B=]C`): it stands for the rest of
// the current branch, up to the `]` that closes it (cpfg `generate.c`,
// RconDiff/skipright). It is no module of the word: a right context's
// FormalModule::symbol holds this value for it (symbol ids end at 65534).
inline constexpr SymbolId kRestOfBranch = 0xFFFF;

// Brackets a right context may nest (`A > [[[B]]]` is 3); deeper is a parse
// error.
inline constexpr int kMaxRightContextNesting = 64;

struct Production {
  std::vector<FormalModule> left;  // in word order; empty = any
  FormalModule pred;
  std::vector<FormalModule> right;  // may contain brackets; empty = any
  uint16_t formalCount = 0;
  // Local variables of the statement blocks: slots after the formals, set
  // to 0 each time the production is tried.
  uint16_t localCount = 0;
  std::optional<Expr> condition;  // none = always true
  std::optional<Expr> weight;     // none = not stochastic
  Successor successor;
  SourceLoc loc;  // of the predecessor (Grammar::SourceLine has its text)
  // Columns of the parts, for run-time error messages.
  int conditionColumn = 0, weightColumn = 0;
  // A production continued over several lines (a trailing `\`, cpfg's
  // indented continuation) is read as one line; each piece says where its
  // columns came from: columns from `at` + 1 on are on `line`, starting at
  // `column` there. Empty: one line.
  struct LinePiece {
    int at = 0, line = 0, column = 1;
  };
  std::vector<LinePiece> pieces;
  // cpfg's `PRED : {pre} COND {post} --> ...`: pre runs before the
  // condition is evaluated (whether or not it holds), post when it holds.
  // (Cold: after the fields the derivation reads for every module.)
  std::optional<Expr> preBlock, postBlock;
  // cpfg's predecessor of several modules (`A B --> C`): the modules after
  // `pred`, matched on the modules right after it in the word (no skipping);
  // the successor replaces them all, and the right context starts after the
  // last. Empty for the usual one-module predecessor.
  std::vector<FormalModule> predTail;
  // The L-system block the production belongs to (Grammar::lsystems; 0 is
  // the main one): it rewrites only modules inside that sub-L-system.
  uint16_t lsystem = 0;
  // The file position of a column of the production as read.
  SourceLoc LocOf(int column) const;

  bool HasContext() const { return !left.empty() || !right.empty(); }
  size_t PredLength() const { return 1 + predTail.size(); }
  bool HasBlocks() const { return preBlock || postBlock || !successor.blocks.empty(); }
};

struct Section {
  std::vector<Production> productions;          // file order
  std::vector<std::vector<uint32_t>> bySymbol;  // symbol id -> production indices
  int maxDepth = 1;                             // decomposition/interpretation passes

  bool empty() const { return productions.empty(); }
};

// `environment: KIND ITEM ...` (docs/grammar.md, "Environment"): which
// environment answers the grammar's ?E queries. The parser reads only its
// form (a kind word, then `key=value`, `name(v, ...)` or bare words, the
// values constant expressions); the plant library gives it meaning and
// reports an unknown kind or key at its location.
struct EnvironmentStatement {
  struct Item {
    std::string name;            // the key, the function name or the bare word
    std::vector<double> values;  // one for key=value, the arguments of name(...)
    bool call = false;           // name(...)
    bool keyValue = false;       // key=value
    SourceLoc loc;               // of the name
  };
  std::string kind;
  SourceLoc loc;  // of the kind word
  std::vector<Item> items;
};

struct Tropism {
  double x = 0, y = -1, z = 0, susceptibility = 0;
};

// One of cpfg's newer tropisms (vlab cpfg movements.c), from a view file's
// `tropism:` or `torque:` line, in the order the file gives them: @Ts(i, e),
// @Ti(i, d) and @Td(i, d) address the i-th (from 1). cpfg keeps at most
// kMaxMovements.
struct Movement {
  bool torque = false;  // `torque:`: turns U about H (else `tropism:`: turns H)
  // T normalised, times the intensity I when the line gives one (cpfg clamps
  // I / |T| to [-1, 1]).
  double x = 0, y = -1, z = 0;
  double angle = 0;           // A: degrees between T and the direction H bends toward
  double elasticity = 0;      // E: at the start of each interpretation
  double elasticityStep = 0;  // S: what @Ti(i) and @Td(i) add and subtract
};
inline constexpr int kMaxMovements = 10;  // cpfg's MAXMOVEMENTS

// One `lsystem:` block of a file (cpfg's sub-L-systems): the first is the
// main L-system, whose axiom and derivation length are used; each later
// one has the number its `lsystem:` line gives. In a word, `?(id, scale)`
// starts the sub-L-system numbered id and `$` ends it: the modules between
// are rewritten by that block's productions only (decomposition and
// interpretation too), and the turtle multiplies its step and width by
// scale there (docs/cpfg.md, "Sub-L-systems").
struct LsystemBlock {
  int id = 0;        // the number of its `lsystem:` line (cpfg: atof of the label)
  std::string name;  // the label as written
  SourceLoc loc;     // of the `lsystem:` line
  // Its ignore:/consider: (per symbol id, 1: skipped by context matching);
  // empty for the main L-system, whose table is Grammar::contextSkip.
  std::vector<uint8_t> contextSkip;
};

struct Grammar {
  std::string name;  // `lsystem:` or the file name
  std::string path;  // main file
  // The main file is a cpfg file (`.l`): drawn by cpfg's turtle, which has
  // no `'` (Sylva's grammars step the colour index with it).
  bool cpfgFile = false;
  int derivationLength = 0;
  double angle = 90;  // degrees
  double step = 1;
  double width = 1;
  double widthFactor = 0.7;
  double widthIncrement = 0;  // `width increment:` (cpfg): ! and # subtract/add it; 0: factor
  double widthScale = 1;      // drawing: diameter = width x widthScale (cpfg's pixel widths)
  std::optional<Tropism> tropism;
  std::vector<Movement> movements;  // a cpfg view file's `tropism:` and `torque:` lines
  std::optional<EnvironmentStatement> environment;  // `environment:`
  // From a cpfg view file (app/view_file.h): the colour index the turtle
  // starts with, the step of `;` and `,`, and of @Ti/@Td.
  int initialColor = 0;
  int colorIncrement = 1;
  double elasticityIncrement = 0;
  uint64_t seed = 1;
  // `palette: #rrggbb ...`: material colour of each colour index (sRGB as
  // written, 0..1); empty: the exporters' default palette.
  std::vector<std::array<float, 3>> palette;

  SymbolTable symbols;
  Successor axiom;  // parameters are evaluated when a derivation starts (seed)
  SourceLoc axiomLoc;
  Section main, decomposition, interpretation;

  // Per symbol id: 1 when context matching skips it (ignore:/consider:).
  std::vector<uint8_t> contextSkip;
  std::optional<SymbolId> cutSymbol;  // the id of `%` when the grammar uses it
  // The L-system blocks, main first (one at least).
  std::vector<LsystemBlock> lsystems;
  // Several blocks, or `?(id)` / `?(id, scale)` modules: the derivation
  // then tracks which block each module belongs to (one thread, left to
  // right, as cpfg), and `$` ends a sub-L-system instead of rolling the
  // turtle (cpfg's `$`).
  bool subLsystems = false;
  // Some production has a predecessor of several modules.
  bool multiModulePredecessors = false;
  bool usesContext = false;  // some production has a context
  bool usesRandom = false;   // weights or random functions anywhere

  std::unordered_map<std::string, double> constants;  // after -D overrides

  // Global variables (cpfg): the names assigned in the Start:, StartEach:,
  // EndEach: and End: blocks, 0 until assigned. Start runs before the
  // axiom is built, StartEach before each derivation step, EndEach after it
  // (after decomposition and cut), End after the last step.
  std::vector<std::string> globals;
  // Their values before Start: runs (empty: all 0); set by array initialisers.
  std::vector<double> globalInitial;
  // cpfg arrays (`define: { array a[3]; }`): elements are globals
  // [base, base + size), named "a[0]", ... in `globals`.
  std::vector<ArrayShape> arrays;
  // The hidden global that `srand(seed);` sets (-1: none; NaN until
  // called). After Start: a finite value there is the derivation's seed, as
  // `seed:` (a --seed given to the command still wins over Start:'s srand).
  int srandGlobal = -1;
  // srand is called outside Start: (a production, StartEach:, ...): each
  // module's random numbers are then drawn from the value the hidden global
  // holds when the module is rewritten (in word order), a global block's
  // from the value when it runs.
  bool reseeds = false;
  // The hidden global that cpfg's `stop(v);` sets (-1: none; NaN until
  // called): a value other than 1 at the end of a step ends the derivation
  // there (Derivation::stopped).
  int stopGlobal = -1;
  // Text parameters of modules (cpfg's `@L("label")`), in file order: a
  // text's value as a parameter is its index here.
  std::vector<std::string> strings;
  // cpfg function files (`functions: a.func b.func`), for func(id, x).
  std::vector<std::shared_ptr<const CpfgFunction>> functions;
  // cpfg's `ring lsystem`: the word is a ring for context matching, its
  // last module the left neighbour of its first (lsys/matcher.h).
  bool ring = false;
  // cpfg curve files (a view file's `curve:` lines), for curveX/Y/Z(id, t)
  // and curveGAL(id).
  std::vector<std::shared_ptr<const CpfgCurve>> curves;
  std::optional<Expr> startBlock, startEachBlock, endEachBlock, endBlock;
  // cpfg data files the blocks read (`fopen(NAME, "r")`, `fscanf`), read
  // when parsed; null when there are none. A derivation starts with none
  // open; afterwards ShortReads() says where fscanf stopped early.
  std::shared_ptr<CpfgDataFiles> dataFiles;
  // Where the grammar indexes its arrays (null: it has none); after a
  // derivation, Warnings() says which arrays were indexed out of bounds
  // (read at the nearest element, as cpfg does).
  std::shared_ptr<ArrayBounds> arrayBounds;
  // Some production assigns a global variable: its steps are then rewritten
  // left to right on one thread, as cpfg does, so the assignments happen in
  // word order.
  bool productionsWriteGlobals = false;

  // Where each module name is first written (axiom or successor), so later
  // stages can point into the grammar (an unknown surface `~name`).
  struct Use {
    SourceLoc loc;
  };
  std::unordered_map<std::string, Use> symbolLoc;

  // The text of every file read (the main file, then each #include), kept
  // so that a diagnostic can quote its line when it is made; locations store
  // only file, line and column.
  struct SourceFile {
    std::string path;
    std::shared_ptr<const std::string> text;
    std::vector<size_t> lineStarts;  // byte offset of line n at [n - 1]
  };
  std::vector<SourceFile> sources;
  // The text of line loc.line of loc.file, without its line break; empty
  // when the file or line is unknown. Points into `sources`.
  std::string_view SourceLine(const SourceLoc& loc) const;
};

}  // namespace sylva::lsys
