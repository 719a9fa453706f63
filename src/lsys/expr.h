// Expressions of the grammar language, compiled once to a compact stack
// code and evaluated per module with no allocation, map lookup or string
// work.
//
// Constant sub-expressions (numbers, #define constants, pi and the pure
// functions of them) are folded at compile time. A compiled Expr is one of:
//   a constant            (most successor parameters: `F(1)`, `+(a0)`)
//   a formal parameter    (`F(l)`)
//   code                  (up to kMaxStack deep)
// A statement block (cpfg's `{ y = x*2; if (y > 1) z = 1; else z = 2; }`)
// compiles to the same code with stores: Exec runs it for its effects on
// the variables (locals after the formals, and the globals).
// Run-time failures (division by zero, a result that is not finite, a
// function outside its domain) are reported with the column of the
// operation that failed, never turned into NaN.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/rng.h"

namespace sylva::lsys {

class CpfgFunction;
class CpfgCurve;
class CpfgDataFiles;
class ArrayBounds;

enum class OpCode : uint8_t {
  kConst,
  kFormal,
  kNeg,
  kNot,
  kAdd,
  kSub,
  kMul,
  kDiv,
  kMod,
  kPow,
  kEq,
  kNe,
  kLt,
  kLe,
  kGt,
  kGe,
  kAndJump,  // if top == 0: top = 0 and jump; else pop
  kOrJump,   // if top != 0: top = 1 and jump; else pop
  kToBool,
  kJumpIfZero,  // pop; jump if zero
  kJump,
  kSin,
  kCos,
  kTan,
  kAsin,
  kAcos,
  kAtan,
  kAtan2,
  kSqrt,
  kExp,
  kLog,
  kPowFn,
  kAbs,
  kFloor,
  kCeil,
  kMin,
  kMax,
  kClamp,
  kSign,
  kTrunc,
  kRan,
  kUniform,
  kNormal,
  kBran,         // cpfg bran(a, b): beta distribution
  kBiran,        // cpfg biran(n, p): binomial distribution
  kFunc,         // cpfg func(id, x): top = funcs_[arg]->Value(top)
  kCurve,        // cpfg curveX/Y/Z(id, t): top = coordinate arg % 3 of curves_[arg / 3] at top
  kGlobal,       // push globals[arg]
  kStore,        // pop into vars[arg] (a formal slot or a local)
  kStoreGlobal,  // pop into globals[arg]
  kLoop,         // jump back to arg; counts iterations (kMaxLoopIterations)
  // cpfg arrays, kept in the globals: an element's offset is built one
  // index at a time (kIndex: top-1 = top-1 * arg + top, 0 <= top < arg;
  // value: the index site in the grammar's ArrayBounds, which an index out
  // of bounds is noted at and clamped as cpfg does, or 0: an error), then
  // read or written at globals[arg + offset].
  kIndex,
  kGlobalAt,       // top = globals[arg + top]
  kStoreGlobalAt,  // value = pop, offset = pop: globals[arg + offset] = value
  // cpfg's data files (lsys/cpfg_data_files.h), in statement blocks only.
  kFopen,   // push a new handle reading data file arg
  kFclose,  // pop a handle and close it
  // fscanf call arg: below the top, the handle, then per address [its
  // array offset] and its value; the values are replaced by what is read
  // and the handle by fscanf's count, for the stores that follow.
  kFscanf,
  kDup,  // push a copy of the top
  kPop,  // drop the top
};

// A `while` loop in a statement block that runs more often than this in one
// execution of the block is an error at the `while`, never a hang.
inline constexpr uint32_t kMaxLoopIterations = 1000000;

struct Instr {  // 16 bytes
  OpCode op;
  uint32_t arg;  // formal slot or jump target
  double value;  // constant
};

struct EvalError {
  int column = 0;
  std::string message;
};

class Expr {
 public:
  enum class Kind : uint8_t { kConstant, kFormal, kCode };

  static Expr Constant(double v);
  static Expr Formal(uint32_t slot);

  Kind kind() const { return kind_; }
  bool IsConstant() const { return kind_ == Kind::kConstant; }
  double constant() const { return constant_; }
  bool UsesRandom() const { return usesRandom_; }

  // Evaluates with the given formal values; random functions draw from rng.
  // Returns false and fills *err on a run-time failure.
  // globals: the grammar's global variables (null when it has none).
  bool Eval(const double* formals, RandomStream& rng, double* out, EvalError* err,
            const double* globals = nullptr) const {
    if (kind_ == Kind::kConstant) {
      *out = constant_;
      return true;
    }
    if (kind_ == Kind::kFormal) {
      *out = formals[slot_];
      return true;
    }
    return Run(const_cast<double*>(formals), const_cast<double*>(globals), rng, out, err);
  }
  // Runs a statement block: assigns vars (formals, then locals) and globals.
  bool Exec(double* vars, double* globals, RandomStream& rng, EvalError* err) const {
    if (kind_ != Kind::kCode) return true;  // an empty block
    return Run(vars, globals, rng, nullptr, err);
  }
  bool IsBlock() const { return isBlock_; }

  static constexpr int kMaxStack = 64;

 private:
  friend class ExprCompiler;
  // out null: a statement block (nothing left on the stack).
  bool Run(double* vars, double* globals, RandomStream& rng, double* out, EvalError* err) const;

  Kind kind_ = Kind::kConstant;
  bool usesRandom_ = false;
  bool isBlock_ = false;
  uint32_t slot_ = 0;
  double constant_ = 0;
  std::vector<Instr> code_;
  std::vector<uint32_t> columns_;  // per instruction: column of the operation, for errors
  std::vector<std::shared_ptr<const CpfgFunction>> funcs_;  // of kFunc: the grammar's functions
  std::vector<std::shared_ptr<const CpfgCurve>> curves_;    // of kCurve: the grammar's curves
  std::shared_ptr<CpfgDataFiles> files_;  // of kFopen, kFscanf, kFclose: the grammar's data files
  std::shared_ptr<ArrayBounds> bounds_;   // of kIndex with a site: the grammar's
};

}  // namespace sylva::lsys
