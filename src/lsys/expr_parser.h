// Parsing expressions from grammar text into Expr.
//
// Grammar (C precedence, `^` is power and binds tighter than unary minus on
// its right: -2^2 = -4):
//   ternary := or ['?' ternary ':' ternary]
//   or      := and {'||' and}        and := eq {'&&' eq}
//   eq      := rel {('=='|'!=') rel} rel := add {('<'|'<='|'>'|'>=') add}
//   add     := mul {('+'|'-') mul}   mul := unary {('*'|'/'|'%') unary}
//   unary   := ('-'|'+'|'!') unary | power
//   power   := primary ['^' unary]
//   primary := number | name | name '(' args ')' | '(' ternary ')'
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "core/diagnostic.h"
#include "lsys/expr.h"

namespace sylva::lsys {

// How deeply parentheses, unary operators, '^', '?:' and function calls may
// nest in one expression; deeper is an error ("expression nested deeper
// than 48"). Chains of binary operators (`1+1+...+1`) have no limit.
inline constexpr int kMaxExprNesting = 48;

// `#define NAME(a, b) body`: a function written in the grammar (cpfg files
// use the C preprocessor's). A call `NAME(x, y)` is the body with each
// parameter replaced by its argument expression, as the preprocessor would
// (an argument with a random function is drawn once per use); errors inside
// the body point at the call. Macros may call earlier macros.
struct ExprMacro {
  std::vector<std::string> params;
  std::string body;  // checked when defined
};

// A cpfg array (`define: { array a[3][2]; }`): global variables
// globals[base ...] in row-major order, indexed from 0.
struct ArrayShape {
  std::string name;
  std::vector<uint32_t> dims;
  uint32_t base = 0;
  size_t Size() const {
    size_t n = 1;
    for (uint32_t d : dims) n *= d;
    return n;
  }
};

// What names mean inside one expression.
struct ExprParseError {
  int column = 0;
  int length = 1;
  std::string message;
  // The text is an expression, but computing a constant part of it failed
  // (division by zero, say).
  bool evaluation = false;
};

struct ExprScope {
  const std::unordered_map<std::string, double>* constants = nullptr;
  std::unordered_set<std::string>* usedConstants = nullptr;  // may be null; macros too
  const std::vector<std::string>* formals = nullptr;         // slot = index
  const std::unordered_map<std::string, ExprMacro>* macros = nullptr;
  // Local variables of a production (cpfg statement blocks): slot =
  // formals->size() + index. An assignment in a block to a name that is
  // no formal, local or global adds it here (null: not allowed).
  std::vector<std::string>* locals = nullptr;
  // Global variables (assigned in Start:, StartEach:, EndEach:, End:):
  // slot = index into the grammar's globals.
  const std::vector<std::string>* globals = nullptr;
  // Set when a block assigns a global variable.
  bool* writesGlobal = nullptr;
  // Where cpfg's output calls in statement blocks go (`printf(...);`,
  // `fprintf(...);`, `fclose(...);`, `fflush(...);`, `f = fopen(NAME, "w");`):
  // Sylva writes no output from a grammar, so they compile to nothing (fopen
  // to 0) and each is noted here, column and message, for the caller to warn
  // about. Null: they are errors.
  std::vector<ExprParseError>* outputCalls = nullptr;
  // A name that nothing defines (no parameter, local, global, constant,
  // macro or array): with this set it reads 0 and is noted here (column,
  // length, the name as message) for the caller to warn about, as cpfg's
  // parser does ("Identifier ... not previously defined"); null: an error.
  std::vector<ExprParseError>* undefinedNames = nullptr;
  // cpfg's data files (`fp = fopen(NAME, "r");`, `fscanf(fp, "%lf", &x);`,
  // `fclose(fp);` in blocks): files are read into it when the block is
  // parsed. Null: reading files is an error.
  const std::shared_ptr<CpfgDataFiles>* dataFiles = nullptr;
  // cpfg function files, for `func(id, x)`: id 1 is the first.
  const std::vector<std::shared_ptr<const CpfgFunction>>* functions = nullptr;
  // cpfg curve files, for `curveX(id, t)` ... and `curveGAL(id)`: id 1 is the first.
  const std::vector<std::shared_ptr<const CpfgCurve>>* curves = nullptr;
  // cpfg arrays: `a[i][j]` in expressions, `a[i][j] = v;` in blocks.
  const std::vector<ArrayShape>* arrays = nullptr;
  // Where an index out of bounds is noted (lsys/array_bounds.h): indexSite
  // registers the `dimension`-th index of `array` written at `column` and
  // returns its site (ArrayBounds::AddSite). Unset: such an index is an
  // evaluation error.
  std::function<uint32_t(int column, const ArrayShape& array, int dimension)> indexSite = nullptr;
  std::shared_ptr<ArrayBounds> arrayBounds = nullptr;
  // The hidden global slot `srand(seed);` stores to (-1: srand is an error
  // here). The derivation draws random numbers from that seed once it is
  // set (Grammar::srandGlobal).
  int srandSlot = -1;
  // The hidden global slot `stop(v);` stores v to (-1: stop is an error
  // here): v other than 1 ends the derivation after the step
  // (Grammar::stopGlobal).
  int stopSlot = -1;
};

// Parses one expression starting at text[pos]; stops before the first
// character that cannot continue it (',' ')' ':' or end) and sets *pos
// there. Columns in errors are 1 + byte offset into `text` + colBase.

bool ParseExpr(std::string_view text, size_t* pos, const ExprScope& scope, Expr* out,
               ExprParseError* err);

// A cpfg statement block starting at text[*pos] == '{', to its matching
// '}' (*pos is set just past it):
//   block := '{' {stmt} '}'
//   stmt  := block | NAME ('=' | '+=' | '-=' | '*=' | '/=') expr ';'
//          | 'if' '(' expr ')' stmt ['else' stmt]
//          | 'while' '(' expr ')' stmt | 'do' stmt 'while' '(' expr ')' ';' | ';'
// The `;` before a `}` may be left out. Out is a block Expr (Expr::Exec).
bool ParseBlock(std::string_view text, size_t* pos, const ExprScope& scope, Expr* out,
                ExprParseError* err);

// Whether the '{' at text[pos] starts a statement block rather than a
// polygon: the text after it (or, when nothing follows it on the line, the
// text of `next`) starts with a statement: `NAME =`, `NAME op=`, `if (`,
// `while (`, `do`, a call of cpfg's `printf`, `fprintf`, `fclose`,
// `fflush`, `srand` or `stop`, or it is `{ }` with only spaces or a `;`
// inside.
bool IsStatementBlock(std::string_view text, size_t pos, std::string_view next = {});

}  // namespace sylva::lsys
