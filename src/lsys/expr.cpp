// Expression parser, constant folder, code generator and stack machine.
#include "lsys/expr.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "core/math.h"
#include "lsys/array_bounds.h"
#include "lsys/cpfg_curve.h"
#include "lsys/cpfg_data_files.h"
#include "lsys/cpfg_function.h"
#include "lsys/expr_parser.h"

namespace sylva::lsys {

Expr Expr::Constant(double v) {
  Expr e;
  e.kind_ = Kind::kConstant;
  e.constant_ = v;
  return e;
}

Expr Expr::Formal(uint32_t slot) {
  Expr e;
  e.kind_ = Kind::kFormal;
  e.slot_ = slot;
  return e;
}

// ---------------------------------------------------------------------------
// Evaluation of one operation on values (shared by folding and the VM).

static bool Fail(EvalError* err, int column, const char* msg) {
  if (err) {
    err->column = column;
    err->message = msg;
  }
  return false;
}

static bool Fail(EvalError* err, int column, const std::string& msg) {
  return Fail(err, column, msg.c_str());
}

static bool Finite(double v, EvalError* err, int column, const char* what) {
  if (std::isfinite(v)) return true;
  return Fail(err, column, what);
}

// Applies a pure (non-random, non-jump) operation to args; result in *out.
static bool ApplyPure(OpCode op, const double* a, double* out, EvalError* err, int col) {
  switch (op) {
    case OpCode::kNeg:
      *out = -a[0];
      return true;
    case OpCode::kNot:
      *out = a[0] == 0 ? 1 : 0;
      return true;
    case OpCode::kToBool:
      *out = a[0] != 0 ? 1 : 0;
      return true;
    case OpCode::kAdd:
      *out = a[0] + a[1];
      return Finite(*out, err, col, "overflow in '+'");
    case OpCode::kSub:
      *out = a[0] - a[1];
      return Finite(*out, err, col, "overflow in '-'");
    case OpCode::kMul:
      *out = a[0] * a[1];
      return Finite(*out, err, col, "overflow in '*'");
    case OpCode::kDiv:
      if (a[1] == 0) return Fail(err, col, "division by zero");
      *out = a[0] / a[1];
      return Finite(*out, err, col, "overflow in '/'");
    case OpCode::kMod:
      if (a[1] == 0) return Fail(err, col, "modulo by zero");
      *out = std::fmod(a[0], a[1]);
      return true;
    case OpCode::kPow:
    case OpCode::kPowFn:
      *out = std::pow(a[0], a[1]);
      return Finite(*out, err, col, "power is not a finite number (negative base, or overflow)");
    case OpCode::kEq:
      *out = a[0] == a[1];
      return true;
    case OpCode::kNe:
      *out = a[0] != a[1];
      return true;
    case OpCode::kLt:
      *out = a[0] < a[1];
      return true;
    case OpCode::kLe:
      *out = a[0] <= a[1];
      return true;
    case OpCode::kGt:
      *out = a[0] > a[1];
      return true;
    case OpCode::kGe:
      *out = a[0] >= a[1];
      return true;
    case OpCode::kSin:
      *out = std::sin(a[0] * kDegToRad);
      return true;
    case OpCode::kCos:
      *out = std::cos(a[0] * kDegToRad);
      return true;
    case OpCode::kTan:
      *out = std::tan(a[0] * kDegToRad);
      return Finite(*out, err, col, "tan is infinite here");
    case OpCode::kAsin:
      if (a[0] < -1 || a[0] > 1) return Fail(err, col, "asin argument outside [-1, 1]");
      *out = std::asin(a[0]) * kRadToDeg;
      return true;
    case OpCode::kAcos:
      if (a[0] < -1 || a[0] > 1) return Fail(err, col, "acos argument outside [-1, 1]");
      *out = std::acos(a[0]) * kRadToDeg;
      return true;
    case OpCode::kAtan:
      *out = std::atan(a[0]) * kRadToDeg;
      return true;
    case OpCode::kAtan2:
      *out = std::atan2(a[0], a[1]) * kRadToDeg;
      return true;
    case OpCode::kSqrt:
      if (a[0] < 0) return Fail(err, col, "sqrt of a negative number");
      *out = std::sqrt(a[0]);
      return true;
    case OpCode::kExp:
      *out = std::exp(a[0]);
      return Finite(*out, err, col, "exp overflows");
    case OpCode::kLog:
      if (a[0] <= 0) return Fail(err, col, "log of a number that is not positive");
      *out = std::log(a[0]);
      return true;
    case OpCode::kAbs:
      *out = std::fabs(a[0]);
      return true;
    case OpCode::kFloor:
      *out = std::floor(a[0]);
      return true;
    case OpCode::kCeil:
      *out = std::ceil(a[0]);
      return true;
    case OpCode::kTrunc:
      *out = std::trunc(a[0]);
      return true;
    case OpCode::kSign:
      *out = a[0] > 0 ? 1 : (a[0] < 0 ? -1 : 0);
      return true;
    case OpCode::kMin:
      *out = a[0] < a[1] ? a[0] : a[1];
      return true;
    case OpCode::kMax:
      *out = a[0] > a[1] ? a[0] : a[1];
      return true;
    case OpCode::kClamp:
      *out = a[0] < a[1] ? a[1] : (a[0] > a[2] ? a[2] : a[0]);
      return true;
    default:
      return Fail(err, col, "internal error: not a pure operation");
  }
}

static int OpArity(OpCode op) {
  switch (op) {
    case OpCode::kNeg:
    case OpCode::kNot:
    case OpCode::kToBool:
    case OpCode::kSin:
    case OpCode::kCos:
    case OpCode::kTan:
    case OpCode::kAsin:
    case OpCode::kAcos:
    case OpCode::kAtan:
    case OpCode::kSqrt:
    case OpCode::kExp:
    case OpCode::kLog:
    case OpCode::kAbs:
    case OpCode::kFloor:
    case OpCode::kCeil:
    case OpCode::kSign:
    case OpCode::kTrunc:
    case OpCode::kRan:
    case OpCode::kFunc:
    case OpCode::kCurve:
      return 1;
    case OpCode::kClamp:
      return 3;
    default:
      return 2;
  }
}

// Gamma(shape, 1) by Marsaglia & Tsang, "A simple method for generating
// gamma variables" (ACM TOMS 26(3), 2000); shape < 1 by the boost
// Gamma(shape + 1) * U^(1/shape).
static double Gamma(double shape, RandomStream& rng) {
  double boost = 1;
  if (shape < 1) {
    double u = rng.Uniform();
    if (u < 0x1.0p-60) u = 0x1.0p-60;
    boost = std::pow(u, 1 / shape);
    shape += 1;
  }
  const double d = shape - 1.0 / 3, c = 1 / std::sqrt(9 * d);
  for (;;) {
    double x, v;
    do {
      x = rng.Normal();
      v = 1 + c * x;
    } while (v <= 0);
    v = v * v * v;
    double u = rng.Uniform();
    if (u < 0x1.0p-60) u = 0x1.0p-60;
    if (std::log(u) < 0.5 * x * x + d - d * v + d * std::log(v)) return d * v * boost;
  }
}

// cpfg's bran(a, b): a number in [0, 1] from the beta distribution with
// shapes a, b > 0 (mean a / (a + b)). Null, or why not.
static const char* Beta(double a, double b, RandomStream& rng, double* out) {
  if (!(a > 0 && b > 0)) return "bran(a, b) needs a > 0 and b > 0";
  const double x = Gamma(a, rng), y = Gamma(b, rng);
  *out = x + y > 0 ? x / (x + y) : 0.5;
  return nullptr;
}

// cpfg's biran(n, p): the number of successes in n trials of probability p.
static const char* Binomial(double n, double p, RandomStream& rng, double* out) {
  n = std::trunc(n);  // cpfg: (int) n
  if (!(n >= 0 && n <= 1e6)) return "biran(n, p) needs a number of trials n from 0 to 1000000";
  if (!(p >= 0 && p <= 1)) return "biran(n, p) needs a probability p from 0 to 1";
  double k = 0;
  for (int i = 0; i < int(n); ++i) k += rng.Uniform() < p ? 1 : 0;
  *out = k;
  return nullptr;
}

bool Expr::Run(double* vars, double* globals, RandomStream& rng, double* out,
               EvalError* err) const {
  double stack[kMaxStack];
  int sp = 0;
  uint32_t loops = 0;
  const Instr* code = code_.data();
  const size_t n = code_.size();
  for (size_t pc = 0; pc < n; ++pc) {
    const Instr& in = code[pc];
    switch (in.op) {
      case OpCode::kConst:
        stack[sp++] = in.value;
        break;
      case OpCode::kFormal:
        stack[sp++] = vars[in.arg];
        break;
      case OpCode::kGlobal:
        stack[sp++] = globals[in.arg];
        break;
      case OpCode::kIndex: {
        const double v = stack[--sp];
        double at = std::floor(v);  // cpfg: (int) index
        if (!(v >= 0 && v < double(in.arg))) {
          if (!bounds_ || in.value == 0 || std::isnan(v)) {
            char b[160];
            std::snprintf(b, sizeof b, "array index %.6g is outside 0 to %u", v, in.arg - 1);
            return Fail(err, int(columns_[pc]), b);
          }
          // cpfg uses the nearest element (generate.c, Eval); noted for a warning.
          bounds_->Note(uint32_t(in.value), v);
          at = v < 0 ? 0 : double(in.arg - 1);
        }
        stack[sp - 1] = stack[sp - 1] * in.arg + at;
        break;
      }
      case OpCode::kGlobalAt:
        stack[sp - 1] = globals[in.arg + size_t(stack[sp - 1])];
        break;
      case OpCode::kStoreGlobalAt: {
        const double v = stack[--sp];
        const size_t at = in.arg + size_t(stack[--sp]);
        if (!std::isfinite(v))
          return Fail(err, int(columns_[pc]), "assigned value is not a finite number (overflow)");
        globals[at] = v;
        break;
      }
      case OpCode::kStore:
      case OpCode::kStoreGlobal: {
        const double v = stack[--sp];
        if (!std::isfinite(v))
          return Fail(err, int(columns_[pc]), "assigned value is not a finite number (overflow)");
        (in.op == OpCode::kStore ? vars : globals)[in.arg] = v;
        break;
      }
      case OpCode::kDup:
        stack[sp] = stack[sp - 1];
        ++sp;
        break;
      case OpCode::kPop:
        --sp;
        break;
      case OpCode::kFopen: {
        const double h = files_->Open(in.arg);
        if (h == 0)
          return Fail(err, int(columns_[pc]),
                      "more than " + std::to_string(kMaxOpenDataFiles) +
                          " files opened in one derivation (fopen in a loop?)");
        stack[sp++] = h;
        break;
      }
      case OpCode::kFclose:
        files_->Close(stack[--sp]);
        break;
      case OpCode::kFscanf: {
        const CpfgDataFiles::Call& call = files_->call(in.arg);
        const int targets = int(call.element.size());
        int slots = 1 + targets;
        for (uint8_t e : call.element) slots += e;
        const int base = sp - slots;
        // The addresses' values, in order (an element's offset sits below it).
        int at[kMaxScanValues];
        double values[kMaxScanValues];
        for (int k = 0, q = base + 1; k < targets; ++k, ++q) {
          q += call.element[size_t(k)];
          at[k] = q;
          values[k] = stack[q];
        }
        int count = 0;
        std::string why;
        if (!files_->Scan(stack[base], in.arg, values, &count, &why))
          return Fail(err, int(columns_[pc]), why);
        for (int k = 0; k < targets; ++k) stack[at[k]] = values[k];
        stack[base] = count;
        break;
      }
      case OpCode::kLoop:
        if (++loops > kMaxLoopIterations)
          return Fail(err, int(columns_[pc]),
                      "loop ran more than 1000000 times (a loop that never ends?)");
        pc = size_t(in.arg) - 1;  // arg 0: wraps, and ++pc makes it 0
        break;
      case OpCode::kAdd:
        --sp;
        stack[sp - 1] += stack[sp];
        break;
      case OpCode::kSub:
        --sp;
        stack[sp - 1] -= stack[sp];
        break;
      case OpCode::kMul:
        --sp;
        stack[sp - 1] *= stack[sp];
        break;
      case OpCode::kLt:
        --sp;
        stack[sp - 1] = stack[sp - 1] < stack[sp];
        break;
      case OpCode::kGt:
        --sp;
        stack[sp - 1] = stack[sp - 1] > stack[sp];
        break;
      case OpCode::kAndJump:
        if (stack[sp - 1] == 0) {
          stack[sp - 1] = 0;
          pc = size_t(in.arg) - 1;
        } else {
          --sp;
        }
        break;
      case OpCode::kOrJump:
        if (stack[sp - 1] != 0) {
          stack[sp - 1] = 1;
          pc = size_t(in.arg) - 1;
        } else {
          --sp;
        }
        break;
      case OpCode::kJumpIfZero:
        --sp;
        if (stack[sp] == 0) pc = size_t(in.arg) - 1;
        break;
      case OpCode::kJump:
        pc = size_t(in.arg) - 1;
        break;
      case OpCode::kRan:
        stack[sp - 1] = stack[sp - 1] * rng.Uniform();
        break;
      case OpCode::kUniform:
        --sp;
        stack[sp - 1] = stack[sp - 1] + (stack[sp] - stack[sp - 1]) * rng.Uniform();
        break;
      case OpCode::kNormal:
        --sp;
        stack[sp - 1] = stack[sp - 1] + stack[sp] * rng.Normal();
        break;
      case OpCode::kFunc:
        stack[sp - 1] = funcs_[in.arg]->Value(stack[sp - 1]);
        break;
      case OpCode::kCurve:
        stack[sp - 1] = curves_[in.arg / 3]->AtLength(stack[sp - 1])[int(in.arg % 3)];
        break;
      case OpCode::kBran:
      case OpCode::kBiran: {
        --sp;
        const char* why = in.op == OpCode::kBran
                              ? Beta(stack[sp - 1], stack[sp], rng, &stack[sp - 1])
                              : Binomial(stack[sp - 1], stack[sp], rng, &stack[sp - 1]);
        if (why) return Fail(err, int(columns_[pc]), why);
        break;
      }
      default: {
        int k = OpArity(in.op);
        sp -= k;
        double r;
        if (!ApplyPure(in.op, stack + sp, &r, err, 0)) {
          if (err) err->column = int(columns_[pc]);
          return false;
        }
        stack[sp++] = r;
      }
    }
  }
  if (!out) return true;  // a statement block
  *out = stack[0];
  // Adds and multiplies skip their own checks in the loop above.
  if (!std::isfinite(*out))
    return Fail(err, columns_.empty() ? 0 : int(columns_.back()),
                "result is not a finite number (overflow)");
  return true;
}

// ---------------------------------------------------------------------------
// Parsing to an AST, folding, emitting.

namespace {

struct Node {
  OpCode op;
  int column;
  double value = 0;
  uint32_t slot = 0;
  std::vector<std::unique_ptr<Node>> kids;
  bool ternary = false;

  Node() = default;
  Node(Node&&) = default;
  Node& operator=(Node&&) = default;
  // A flat chain `1+1+...+1` is a tree as deep as it is long: free it with a
  // work list, not recursion.
  ~Node() {
    std::vector<std::unique_ptr<Node>> pending;
    for (auto& k : kids) {
      if (k) pending.push_back(std::move(k));
    }
    while (!pending.empty()) {
      std::unique_ptr<Node> n = std::move(pending.back());
      pending.pop_back();
      for (auto& k : n->kids) {
        if (k) pending.push_back(std::move(k));
      }
    }
  }
};
using NodePtr = std::unique_ptr<Node>;

struct FunctionInfo {
  const char* name;
  OpCode op;
  int args;
};

constexpr FunctionInfo kFunctions[] = {
    {"sin", OpCode::kSin, 1},       {"cos", OpCode::kCos, 1},     {"tan", OpCode::kTan, 1},
    {"asin", OpCode::kAsin, 1},     {"acos", OpCode::kAcos, 1},   {"atan", OpCode::kAtan, 1},
    {"atan2", OpCode::kAtan2, 2},   {"sqrt", OpCode::kSqrt, 1},   {"exp", OpCode::kExp, 1},
    {"log", OpCode::kLog, 1},       {"pow", OpCode::kPowFn, 2},   {"abs", OpCode::kAbs, 1},
    {"floor", OpCode::kFloor, 1},   {"ceil", OpCode::kCeil, 1},   {"min", OpCode::kMin, 2},
    {"max", OpCode::kMax, 2},       {"clamp", OpCode::kClamp, 3}, {"sign", OpCode::kSign, 1},
    {"trunc", OpCode::kTrunc, 1},   {"ran", OpCode::kRan, 1},     {"uniform", OpCode::kUniform, 2},
    {"normal", OpCode::kNormal, 2}, {"nran", OpCode::kNormal, 2},  // nran: cpfg's name
    {"fabs", OpCode::kAbs, 1},                                     // cpfg's (C's) name
    {"bran", OpCode::kBran, 2},     {"biran", OpCode::kBiran, 2},
};

// cpfg's functions that Sylva does not have: named as such when called.
constexpr std::string_view kCpfgFunctions[] = {
    "srand",  "inblob", "stop", "printf",         "fprintf",        "fopen",  "fclose",
    "fflush", "fscanf", "play", "setDerivLength", "getDerivLength", "display"};

bool IsRandom(OpCode op) {
  return op == OpCode::kRan || op == OpCode::kUniform || op == OpCode::kNormal ||
         op == OpCode::kBran || op == OpCode::kBiran;
}

// Nesting (parentheses, unary operators, '^', '?:', function arguments)
// recurses in the parser; chains of binary operators do not.
constexpr int kMaxDepth = kMaxExprNesting;

class Parser {
 public:
  Parser(std::string_view text, size_t pos, const ExprScope& scope, ExprParseError* err)
      : t_(text), p_(pos), scope_(scope), err_(err) {}

  NodePtr Parse() { return Ternary(baseDepth_); }
  size_t pos() const { return p_; }
  void SkipTrailingSpace() { SkipSpace(); }

 private:
  void SkipSpace() {
    while (p_ < t_.size() && (t_[p_] == ' ' || t_[p_] == '\t' || t_[p_] == '\r')) ++p_;
  }
  bool Peek(std::string_view s) {
    SkipSpace();
    return t_.substr(p_, s.size()) == s;
  }
  bool Accept(std::string_view s) {
    if (!Peek(s)) return false;
    p_ += s.size();
    return true;
  }
  int Col() const { return int(p_) + 1; }
  NodePtr Error(int col, std::string msg, int len = 1) {
    if (err_->message.empty()) {
      err_->column = col;
      err_->length = len;
      err_->message = std::move(msg);
    }
    return nullptr;
  }
  NodePtr Make(OpCode op, int col, NodePtr a = nullptr, NodePtr b = nullptr) {
    auto n = std::make_unique<Node>();
    n->op = op;
    n->column = macroColumn_ ? macroColumn_ : col;
    if (a) n->kids.push_back(std::move(a));
    if (b) n->kids.push_back(std::move(b));
    return n;
  }

  NodePtr Ternary(int depth) {
    if (depth > kMaxDepth)
      return Error(Col(), "expression nested deeper than " + std::to_string(kMaxDepth));
    NodePtr c = Binary(0, depth);
    if (!c) return nullptr;
    SkipSpace();
    int col = Col();
    if (!Accept("?")) return c;
    NodePtr a = Ternary(depth + 1);
    if (!a) return nullptr;
    if (!Accept(":")) return Error(Col(), "expected ':' in conditional expression");
    NodePtr b = Ternary(depth + 1);
    if (!b) return nullptr;
    auto n = Make(OpCode::kJumpIfZero, col, std::move(c), std::move(a));
    n->kids.push_back(std::move(b));
    n->ternary = true;
    return n;
  }

  // Precedence levels 0..5: || && equality relational additive multiplicative.
  NodePtr Binary(int level, int depth) {
    if (level == 6) return Unary(depth);
    NodePtr lhs = Binary(level + 1, depth);
    if (!lhs) return nullptr;
    for (;;) {
      SkipSpace();
      int col = Col();
      OpCode op;
      if (!MatchOp(level, &op)) return lhs;
      NodePtr rhs = Binary(level + 1, depth);
      if (!rhs) return nullptr;
      lhs = Make(op, col, std::move(lhs), std::move(rhs));
    }
  }

  bool MatchOp(int level, OpCode* op) {
    switch (level) {
      case 0:
        if (Accept("||")) {
          *op = OpCode::kOrJump;
          return true;
        }
        return false;
      case 1:
        if (Accept("&&")) {
          *op = OpCode::kAndJump;
          return true;
        }
        return false;
      case 2:
        if (Accept("==")) {
          *op = OpCode::kEq;
          return true;
        }
        if (Accept("!=")) {
          *op = OpCode::kNe;
          return true;
        }
        return false;
      case 3:
        if (Accept("<=")) {
          *op = OpCode::kLe;
          return true;
        }
        if (Accept(">=")) {
          *op = OpCode::kGe;
          return true;
        }
        if (Accept("<")) {
          *op = OpCode::kLt;
          return true;
        }
        if (Accept(">")) {
          *op = OpCode::kGt;
          return true;
        }
        return false;
      case 4:
        if (Accept("+")) {
          *op = OpCode::kAdd;
          return true;
        }
        if (Accept("-")) {
          *op = OpCode::kSub;
          return true;
        }
        return false;
      case 5:
        if (Accept("*")) {
          *op = OpCode::kMul;
          return true;
        }
        if (Accept("/")) {
          *op = OpCode::kDiv;
          return true;
        }
        if (Accept("%")) {
          *op = OpCode::kMod;
          return true;
        }
        return false;
    }
    return false;
  }

  NodePtr Unary(int depth) {
    if (depth > kMaxDepth)
      return Error(Col(), "expression nested deeper than " + std::to_string(kMaxDepth));
    SkipSpace();
    int col = Col();
    if (Accept("-")) {
      NodePtr a = Unary(depth + 1);
      return a ? Make(OpCode::kNeg, col, std::move(a)) : nullptr;
    }
    if (Accept("+")) return Unary(depth + 1);
    if (Peek("!") && !Peek("!=")) {
      ++p_;
      NodePtr a = Unary(depth + 1);
      return a ? Make(OpCode::kNot, col, std::move(a)) : nullptr;
    }
    NodePtr base = Primary(depth);
    if (!base) return nullptr;
    SkipSpace();
    int pcol = Col();
    if (Accept("^")) {
      NodePtr e = Unary(depth + 1);
      if (!e) return nullptr;
      return Make(OpCode::kPow, pcol, std::move(base), std::move(e));
    }
    return base;
  }

  NodePtr Number() {
    int col = Col();
    size_t start = p_;
    while (p_ < t_.size() && std::isdigit(static_cast<unsigned char>(t_[p_]))) ++p_;
    if (p_ < t_.size() && t_[p_] == '.') {
      ++p_;
      while (p_ < t_.size() && std::isdigit(static_cast<unsigned char>(t_[p_]))) ++p_;
    }
    if (p_ < t_.size() && (t_[p_] == 'e' || t_[p_] == 'E')) {
      size_t q = p_ + 1;
      if (q < t_.size() && (t_[q] == '+' || t_[q] == '-')) ++q;
      if (q < t_.size() && std::isdigit(static_cast<unsigned char>(t_[q]))) {
        p_ = q;
        while (p_ < t_.size() && std::isdigit(static_cast<unsigned char>(t_[p_]))) ++p_;
      } else {
        return Error(col, "malformed number: exponent has no digits", int(q - start));
      }
    }
    std::string s(t_.substr(start, p_ - start));
    if (s == ".") return Error(col, "malformed number '.'");
    // A number directly followed by a letter, digit or '.' is malformed (1.2.3, 3x).
    if (p_ < t_.size() &&
        (std::isalnum(static_cast<unsigned char>(t_[p_])) || t_[p_] == '.' || t_[p_] == '_')) {
      size_t q = p_;
      while (q < t_.size() &&
             (std::isalnum(static_cast<unsigned char>(t_[q])) || t_[q] == '.' || t_[q] == '_'))
        ++q;
      return Error(col, "malformed number '" + std::string(t_.substr(start, q - start)) + "'",
                   int(q - start));
    }
    double v = std::strtod(s.c_str(), nullptr);
    if (!std::isfinite(v)) return Error(col, "number out of range '" + s + "'", int(s.size()));
    auto n = Make(OpCode::kConst, col);
    n->value = v;
    return n;
  }

  NodePtr Primary(int depth) {
    SkipSpace();
    int col = Col();
    if (p_ >= t_.size()) return Error(col, "expected an expression");
    char c = t_[p_];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return Number();
    if (c == '(') {
      ++p_;
      NodePtr e = Ternary(depth + 1);
      if (!e) return nullptr;
      if (!Accept(")")) return Error(Col(), "expected ')'");
      return e;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      size_t start = p_;
      while (p_ < t_.size() && (std::isalnum(static_cast<unsigned char>(t_[p_])) || t_[p_] == '_'))
        ++p_;
      std::string name(t_.substr(start, p_ - start));
      int len = int(name.size());
      SkipSpace();
      if (p_ < t_.size() && t_[p_] == '(') return Call(name, col, len, depth);
      if (const ArrayShape* a = FindArray(name)) return Element(*a, col, len, depth);
      // Macro parameters, then formal parameters, shadow constants.
      if (bound_) {
        for (size_t i = 0; i < bound_->names.size(); ++i) {
          if (bound_->names[i] == name) return Clone(*bound_->args[i]);
        }
      }
      if (auto n = Variable(name, col)) return n;
      if (scope_.constants) {
        auto it = scope_.constants->find(name);
        if (it != scope_.constants->end()) {
          if (scope_.usedConstants) scope_.usedConstants->insert(name);
          auto n = Make(OpCode::kConst, col);
          n->value = it->second;
          return n;
        }
      }
      if (name == "pi" || name == "PI") {
        auto n = Make(OpCode::kConst, col);
        n->value = kPi;
        return n;
      }
      for (const auto& f : kFunctions) {
        if (name == f.name) return Error(col, "function '" + name + "' needs arguments", len);
      }
      if (scope_.undefinedNames) {
        scope_.undefinedNames->push_back(ExprParseError{col, len, name});
        auto n = Make(OpCode::kConst, col);
        n->value = 0;
        return n;
      }
      return Error(col, "unknown name '" + name + "' in expression", len);
    }
    if (c == ')' || c == ',' || c == ':')
      return Error(col, "expected an expression before '" + std::string(1, c) + "'");
    char hex[8];
    std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned char>(c));
    std::string shown = static_cast<unsigned char>(c) >= 32 && static_cast<unsigned char>(c) < 127
                            ? std::string(1, c)
                            : std::string(hex);
    return Error(col, "unexpected character '" + shown + "' in expression");
  }

  // The index site of the dimension-th index of `a` at col, or 0.
  double Site(int col, const ArrayShape& a, int dimension) const {
    return scope_.indexSite ? double(scope_.indexSite(col, a, dimension)) : 0;
  }

  const ArrayShape* FindArray(const std::string& name) const {
    if (!scope_.arrays) return nullptr;
    for (const ArrayShape& a : *scope_.arrays)
      if (a.name == name) return &a;
    return nullptr;
  }

  // `a[i][j]`: one index per dimension, each checked when it is evaluated.
  NodePtr Element(const ArrayShape& a, int col, int len, int depth) {
    auto acc = Make(OpCode::kConst, col);
    acc->value = 0;
    int dimension = 1;
    for (uint32_t d : a.dims) {
      SkipSpace();
      if (p_ >= t_.size() || t_[p_] != '[')
        return Error(col,
                     "array '" + a.name + "' needs " + std::to_string(a.dims.size()) +
                         (a.dims.size() == 1 ? " index" : " indices") + ": " + a.name +
                         std::string(a.dims.size() == 1 ? "[i]" : "[i][j]..."),
                     len);
      ++p_;
      NodePtr index = Ternary(depth + 1);
      if (!index) return nullptr;
      if (!Accept("]")) return Error(Col(), "expected ']' after an index of '" + a.name + "'");
      auto ix = Make(OpCode::kIndex, col, std::move(acc), std::move(index));
      ix->slot = d;
      ix->value = Site(col, a, dimension++);
      acc = std::move(ix);
    }
    SkipSpace();
    if (p_ < t_.size() && t_[p_] == '[')
      return Error(Col(), "array '" + a.name + "' has " + std::to_string(a.dims.size()) +
                              (a.dims.size() == 1 ? " dimension" : " dimensions"));
    auto n = Make(OpCode::kGlobalAt, col, std::move(acc));
    n->slot = a.base;
    return n;
  }

  // A formal parameter, local or global variable of this name, or null.
  NodePtr Variable(const std::string& name, int col) {
    uint32_t slot;
    if (FindVar(scope_, name, &slot)) {
      auto n = Make(OpCode::kFormal, col);
      n->slot = slot;
      return n;
    }
    if (scope_.globals) {
      for (size_t i = 0; i < scope_.globals->size(); ++i) {
        if ((*scope_.globals)[i] == name) {
          auto n = Make(OpCode::kGlobal, col);
          n->slot = uint32_t(i);
          return n;
        }
      }
    }
    return nullptr;
  }

 public:
  // The slot of a formal parameter or local variable.
  static bool FindVar(const ExprScope& scope, const std::string& name, uint32_t* slot) {
    const size_t nf = scope.formals ? scope.formals->size() : 0;
    for (size_t i = 0; i < nf; ++i) {
      if ((*scope.formals)[i] == name) {
        *slot = uint32_t(i);
        return true;
      }
    }
    if (scope.locals) {
      for (size_t i = 0; i < scope.locals->size(); ++i) {
        if ((*scope.locals)[i] == name) {
          *slot = uint32_t(nf + i);
          return true;
        }
      }
    }
    return false;
  }

 private:
  // cpfg's func(id, x): id a constant naming one of the grammar's function
  // files (1 is the first).
  NodePtr Func(int col, int len, int depth) {
    ++p_;  // '('
    NodePtr id = Ternary(depth + 1);
    if (!id) return nullptr;
    if (!Accept(",")) return Error(Col(), "func takes 2 arguments: func(id, x)");
    NodePtr x = Ternary(depth + 1);
    if (!x) return nullptr;
    if (!Accept(")")) return Error(Col(), "func takes 2 arguments: func(id, x)");
    const size_t count = scope_.functions ? scope_.functions->size() : 0;
    if (count == 0)
      return Error(col,
                   "func(id, x) needs cpfg function files: name them with "
                   "'functions: FILE.func ...' before the productions, or with "
                   "'function: FILE.func' lines in the view file",
                   len);
    if (id->op != OpCode::kConst || id->value != std::floor(id->value) || id->value < 1 ||
        id->value > double(count)) {
      return Error(col,
                   "func(id, x): id must be a whole number from 1 to " + std::to_string(count) +
                       " (the files of 'functions:')",
                   len);
    }
    auto n = Make(OpCode::kFunc, col, std::move(x));
    n->slot = uint32_t(id->value) - 1;
    return n;
  }

  // cpfg's curveX/Y/Z(id, t) and curveGAL(id) (curveXYZc.cpp): id a
  // constant from 1 to the number of curves; curveGAL is that curve's
  // length, a constant.
  NodePtr Curve(const std::string& name, int col, int len, int depth) {
    const bool length = name == "curveGAL";
    const std::string usage = length ? "curveGAL takes 1 argument: curveGAL(id)"
                                     : name + " takes 2 arguments: " + name + "(id, t)";
    ++p_;  // '('
    NodePtr id = Ternary(depth + 1);
    if (!id) return nullptr;
    NodePtr t;
    if (!length) {
      if (!Accept(",")) return Error(Col(), usage);
      t = Ternary(depth + 1);
      if (!t) return nullptr;
    }
    if (!Accept(")")) return Error(Col(), usage);
    const size_t count = scope_.curves ? scope_.curves->size() : 0;
    if (count == 0)
      return Error(col,
                   name +
                       " needs cpfg curve files: name them with 'curve: FILE.con' lines in "
                       "the view file",
                   len);
    if (id->op != OpCode::kConst || id->value != std::floor(id->value) || id->value < 1 ||
        id->value > double(count)) {
      return Error(col,
                   name + ": id must be a whole number from 1 to " + std::to_string(count) +
                       " (the view file's 'curve:' lines)",
                   len);
    }
    const uint32_t index = uint32_t(id->value) - 1;
    if (length) {
      auto n = Make(OpCode::kConst, col);
      n->value = (*scope_.curves)[index]->Length();
      return n;
    }
    auto n = Make(OpCode::kCurve, col, std::move(t));
    n->slot = index * 3 + uint32_t(name == "curveX" ? 0 : (name == "curveY" ? 1 : 2));
    return n;
  }

  NodePtr Call(const std::string& name, int col, int len, int depth) {
    if (name == "func") return Func(col, len, depth);
    if (name == "curveX" || name == "curveY" || name == "curveZ" || name == "curveGAL")
      return Curve(name, col, len, depth);
    if (scope_.macros) {
      auto it = scope_.macros->find(name);
      if (it != scope_.macros->end()) return Macro(name, it->second, col, len, depth);
    }
    const FunctionInfo* fn = nullptr;
    for (const auto& f : kFunctions) {
      if (name == f.name) fn = &f;
    }
    if (!fn) {
      if (name == "fscanf" || name == "fopen" || name == "fclose")
        return Error(col,
                     "'" + name + "(...)' is read in a statement block as a statement ('" + name +
                         "(...);') or an assignment ('x = " + name +
                         "(...);'), not inside an expression",
                     len);
      for (std::string_view c : kCpfgFunctions) {
        if (name == c)
          return Error(col, "cpfg function '" + name + "' is not supported by Sylva", len);
      }
      return Error(col, "unknown function '" + name + "'", len);
    }
    ++p_;  // '('
    auto n = Make(fn->op, col);
    SkipSpace();
    if (!Accept(")")) {
      for (;;) {
        NodePtr a = Ternary(depth + 1);
        if (!a) return nullptr;
        n->kids.push_back(std::move(a));
        if (Accept(",")) continue;
        if (Accept(")")) break;
        return Error(Col(), "expected ',' or ')' in arguments of '" + name + "'");
      }
    }
    if (int(n->kids.size()) != fn->args) {
      return Error(col,
                   "function '" + name + "' takes " + std::to_string(fn->args) + " argument" +
                       (fn->args == 1 ? "" : "s") + ", given " + std::to_string(n->kids.size()),
                   len);
    }
    return n;
  }

  // A deep copy, by a work list (argument trees may be long operator chains).
  static NodePtr Clone(const Node& root) {
    auto copyOne = [](const Node& n) {
      auto c = std::make_unique<Node>();
      c->op = n.op;
      c->column = n.column;
      c->value = n.value;
      c->slot = n.slot;
      c->ternary = n.ternary;
      return c;
    };
    NodePtr out = copyOne(root);
    std::vector<std::pair<const Node*, Node*>> pending{{&root, out.get()}};
    while (!pending.empty()) {
      auto [src, dst] = pending.back();
      pending.pop_back();
      for (const auto& k : src->kids) {
        dst->kids.push_back(copyOne(*k));
        pending.emplace_back(k.get(), dst->kids.back().get());
      }
    }
    return out;
  }

  // NAME(args) of `#define NAME(params) body`: the body parsed with each
  // parameter bound to a copy of its argument; its own nodes take the
  // call's column.
  NodePtr Macro(const std::string& name, const ExprMacro& m, int col, int len, int depth) {
    if (scope_.usedConstants) scope_.usedConstants->insert(name);
    if (depth + 1 > kMaxDepth)
      return Error(col, "expression nested deeper than " + std::to_string(kMaxDepth), len);
    ++p_;  // '('
    Bound bound;
    bound.names = m.params;
    SkipSpace();
    if (!Accept(")")) {
      for (;;) {
        NodePtr a = Ternary(depth + 1);
        if (!a) return nullptr;
        bound.args.push_back(std::move(a));
        if (Accept(",")) continue;
        if (Accept(")")) break;
        return Error(Col(), "expected ',' or ')' in arguments of '" + name + "'");
      }
    }
    if (bound.args.size() != m.params.size()) {
      return Error(col,
                   "'" + name + "' (#define) takes " + std::to_string(m.params.size()) +
                       " argument" + (m.params.size() == 1 ? "" : "s") + ", given " +
                       std::to_string(bound.args.size()),
                   len);
    }
    ExprParseError inner;
    Parser body(m.body, 0, scope_, &inner);
    body.bound_ = &bound;
    body.macroColumn_ = col;
    body.baseDepth_ = depth + 1;
    NodePtr n = body.Parse();
    if (n) {
      body.SkipTrailingSpace();
      if (body.pos() < m.body.size()) {
        n = nullptr;
        inner.message = "unexpected text after the expression";
      }
    }
    if (!n) return Error(col, "in '" + name + "' (#define): " + inner.message, len);
    return n;
  }

  struct Bound {
    std::vector<std::string> names;
    std::vector<NodePtr> args;
  };

  std::string_view t_;
  size_t p_;
  const ExprScope& scope_;
  ExprParseError* err_;
  const Bound* bound_ = nullptr;  // inside a macro body: its parameters
  int macroColumn_ = 0;           // inside a macro body: the call's column
  int baseDepth_ = 0;
};

}  // namespace

class ExprCompiler {
 public:
  explicit ExprCompiler(ExprParseError* err) : err_(err) {}

  // Folds constant subtrees in place, children first; false on a
  // compile-time error. A work list, not recursion: operator chains make
  // trees as deep as they are long.
  bool Fold(Node& root) {
    struct Frame {
      Node* node;
      size_t next;
    };
    std::vector<Frame> stack{{&root, 0}};
    while (!stack.empty()) {
      Frame& f = stack.back();
      if (f.next < f.node->kids.size()) {
        Node* kid = f.node->kids[f.next++].get();
        stack.push_back({kid, 0});
        continue;
      }
      Node* n = f.node;
      stack.pop_back();
      if (!FoldNode(*n)) return false;
    }
    return true;
  }

  // Folds one node whose children are folded.
  bool FoldNode(Node& n) {
    if (n.op == OpCode::kConst || n.op == OpCode::kFormal || n.op == OpCode::kGlobal ||
        n.op == OpCode::kFunc || n.op == OpCode::kCurve || IsRandom(n.op) ||
        n.op == OpCode::kIndex || n.op == OpCode::kGlobalAt)
      return true;
    for (auto& k : n.kids) {
      if (k->op != OpCode::kConst) {
        // Short-circuit forms fold when their deciding operand is constant.
        return FoldPartial(n);
      }
    }
    double args[3], r;
    if (n.ternary) {
      r = args[0] = n.kids[0]->value != 0 ? n.kids[1]->value : n.kids[2]->value;
    } else if (n.op == OpCode::kAndJump) {
      r = (n.kids[0]->value != 0 && n.kids[1]->value != 0) ? 1 : 0;
    } else if (n.op == OpCode::kOrJump) {
      r = (n.kids[0]->value != 0 || n.kids[1]->value != 0) ? 1 : 0;
    } else {
      for (size_t i = 0; i < n.kids.size(); ++i) args[i] = n.kids[i]->value;
      EvalError e;
      if (!ApplyPure(n.op, args, &r, &e, n.column)) {
        err_->column = e.column;
        err_->message = e.message;
        err_->evaluation = true;
        return false;
      }
    }
    n.op = OpCode::kConst;
    n.value = r;
    n.ternary = false;
    n.kids.clear();
    return true;
  }

  bool FoldPartial(Node& n) {
    const Node& first = *n.kids[0];
    if (first.op != OpCode::kConst) return true;
    NodePtr keep;
    if (n.ternary) {
      keep = std::move(n.kids[first.value != 0 ? 1 : 2]);
    } else if (n.op == OpCode::kAndJump && first.value == 0) {
      n.kids.clear();
      n.op = OpCode::kConst;
      n.value = 0;
      return true;
    } else if (n.op == OpCode::kOrJump && first.value != 0) {
      n.kids.clear();
      n.op = OpCode::kConst;
      n.value = 1;
      return true;
    } else {
      return true;
    }
    Node tmp = std::move(*keep);
    n = std::move(tmp);
    return true;
  }

  // Emits stack code for the tree, in post order with the jumps of '?:',
  // '&&' and '||' between the operands; *maxDepth is the deepest evaluation
  // stack the code reaches. A work list, not recursion (see Fold).
  static void Emit(const Node& root, std::vector<Instr>& code, std::vector<uint32_t>& columns,
                   int* maxDepth) {
    struct Frame {
      const Node* node;
      int depth;            // stack depth the node's value lands at
      size_t next;          // next child to emit
      size_t jump1, jump2;  // instructions to patch
    };
    std::vector<Frame> stack{{&root, 1, 0, 0, 0}};
    while (!stack.empty()) {
      Frame& f = stack.back();
      const Node& n = *f.node;
      auto push = [&](OpCode op, uint32_t arg = 0, double v = 0) {
        code.push_back(Instr{op, arg, v});
        columns.push_back(uint32_t(n.column));
      };
      if (f.depth > *maxDepth) *maxDepth = f.depth;
      if (n.op == OpCode::kConst || n.op == OpCode::kFormal || n.op == OpCode::kGlobal) {
        if (n.op == OpCode::kConst)
          push(OpCode::kConst, 0, n.value);
        else
          push(n.op, n.slot);
        stack.pop_back();
        continue;
      }
      const bool shortCircuit = n.op == OpCode::kAndJump || n.op == OpCode::kOrJump;
      if (f.next < n.kids.size()) {
        size_t i = f.next++;
        int depth = f.depth;
        if (n.ternary) {
          if (i == 1) {
            f.jump1 = code.size();
            push(OpCode::kJumpIfZero);
          } else if (i == 2) {
            f.jump2 = code.size();
            push(OpCode::kJump);
            code[f.jump1].arg = uint32_t(code.size());
          }
        } else if (shortCircuit) {
          if (i == 1) {
            f.jump1 = code.size();
            push(n.op);
          }
        } else {
          depth += int(i);
        }
        stack.push_back({n.kids[i].get(), depth, 0, 0, 0});  // f is invalid from here
        continue;
      }
      if (n.ternary) {
        code[f.jump2].arg = uint32_t(code.size());
      } else if (shortCircuit) {
        push(OpCode::kToBool);
        code[f.jump1].arg = uint32_t(code.size());
      } else {
        push(n.op, n.slot, n.op == OpCode::kIndex ? n.value : 0);  // kIndex: its site
      }
      stack.pop_back();
    }
  }

  // --- statement blocks ---
  // Compiles the block at text[*pos] == '{' into `blockCode`, the statements in
  // order; false with err_ filled on a syntax error.
  bool Block(std::string_view text, size_t* pos, const ExprScope& scope, int depth) {
    if (depth > kMaxExprNesting) return Err(int(*pos) + 1, "statements nested deeper than 48");
    const size_t open = *pos;
    ++*pos;  // '{'
    for (;;) {
      SkipSpace(text, pos);
      if (*pos >= text.size())
        return Err(int(open) + 1, "unclosed '{': the statement block has no '}'");
      if (text[*pos] == '}') {
        ++*pos;
        return true;
      }
      if (!Statement(text, pos, scope, depth + 1)) return false;
    }
  }

  bool Finish(const Node& root, Expr* out) {
    Expr e;
    if (root.op == OpCode::kConst) {
      e = Expr::Constant(root.value);
    } else if (root.op == OpCode::kFormal) {
      e = Expr::Formal(root.slot);
    } else {
      e.kind_ = Expr::Kind::kCode;
      int maxDepth = 0;
      Emit(root, e.code_, e.columns_, &maxDepth);
      if (maxDepth >= Expr::kMaxStack) {
        err_->column = root.column;
        err_->message = "expression too complex (evaluation stack deeper than 64)";
        return false;
      }
      for (const Instr& in : e.code_) e.usesRandom_ |= IsRandom(in.op);
      TakeFunctions(e);
    }
    *out = std::move(e);
    return true;
  }

  // The grammar's function files, when the code calls func(), and its
  // data files, when it reads them.
  void TakeFunctions(Expr& e) const {
    for (const Instr& in : e.code_) {
      if (in.op == OpCode::kFunc && scope_ && scope_->functions) e.funcs_ = *scope_->functions;
      if (in.op == OpCode::kCurve && scope_ && scope_->curves) e.curves_ = *scope_->curves;
      if ((in.op == OpCode::kFopen || in.op == OpCode::kFscanf || in.op == OpCode::kFclose) &&
          scope_ && scope_->dataFiles)
        e.files_ = *scope_->dataFiles;
      if (in.op == OpCode::kIndex && in.value != 0 && scope_) e.bounds_ = scope_->arrayBounds;
    }
  }
  const ExprScope* scope_ = nullptr;

  void TakeBlock(Expr* out) {
    Expr e;
    e.isBlock_ = true;
    if (!blockCode.empty()) {
      e.kind_ = Expr::Kind::kCode;
      e.code_ = std::move(blockCode);
      e.columns_ = std::move(blockColumns);
      for (const Instr& in : e.code_) e.usesRandom_ |= IsRandom(in.op);
      TakeFunctions(e);
    }
    *out = std::move(e);
  }

  std::vector<Instr> blockCode;
  std::vector<uint32_t> blockColumns;
  int blockDepth = 0;

 private:
  static void SkipSpace(std::string_view t, size_t* p) {
    while (*p < t.size() && (t[*p] == ' ' || t[*p] == '\t' || t[*p] == '\r')) ++*p;
  }
  static bool IsIdent(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
  // The keyword `kw` at *p, not followed by a name character.
  static bool Keyword(std::string_view t, size_t p, std::string_view kw) {
    return t.substr(p, kw.size()) == kw &&
           (p + kw.size() >= t.size() || !IsIdent(t[p + kw.size()]));
  }
  bool Err(int column, std::string msg, int len = 1) {
    if (err_->message.empty()) {
      err_->column = column;
      err_->length = len;
      err_->message = std::move(msg);
    }
    return false;
  }
  void Push(OpCode op, uint32_t arg, int column) {
    blockCode.push_back(Instr{op, arg, 0});
    blockColumns.push_back(uint32_t(column));
  }
  // One expression at *pos, folded and emitted.
  bool Expression(std::string_view text, size_t* pos, const ExprScope& scope) {
    Parser p(text, *pos, scope, err_);
    NodePtr root = p.Parse();
    if (!root) return false;
    *pos = p.pos();
    if (!Fold(*root)) return false;
    int depth = 0;
    Emit(*root, blockCode, blockColumns, &depth);
    blockDepth = std::max(blockDepth, depth);
    return true;
  }
  // '(' expression ')'
  bool Condition(std::string_view text, size_t* pos, const ExprScope& scope, const char* what) {
    SkipSpace(text, pos);
    if (*pos >= text.size() || text[*pos] != '(')
      return Err(int(*pos) + 1, std::string("expected '(' after '") + what + "'");
    ++*pos;
    if (!Expression(text, pos, scope)) return false;
    SkipSpace(text, pos);
    if (*pos >= text.size() || text[*pos] != ')')
      return Err(int(*pos) + 1, std::string("expected ')' after the condition of '") + what + "'");
    ++*pos;
    return true;
  }
  // The call's parentheses from text[open] == '(' to the matching ')',
  // "strings" (with their escapes) skipped; *pos is set just past it.
  bool SkipCall(std::string_view text, size_t open, size_t* pos, const std::string& name) {
    int nest = 0;
    for (size_t i = open; i < text.size(); ++i) {
      const char ch = text[i];
      if (ch == '"') {
        for (++i; i < text.size() && text[i] != '"'; ++i)
          if (text[i] == '\\') ++i;
        if (i >= text.size()) return Err(int(open) + 1, "unclosed string in '" + name + "(...)'");
      } else if (ch == '(') {
        ++nest;
      } else if (ch == ')' && --nest == 0) {
        *pos = i + 1;
        return true;
      }
    }
    return Err(int(open) + 1, "unclosed '(' of '" + name + "(...)'");
  }
  // An optional ';' (required unless a '}' follows).
  bool EndOfStatement(std::string_view text, size_t* pos) {
    SkipSpace(text, pos);
    if (*pos < text.size() && text[*pos] == ';') {
      ++*pos;
      return true;
    }
    if (*pos < text.size() && text[*pos] == '}') return true;
    return Err(int(*pos) + 1, "expected ';' after the statement");
  }

  bool Statement(std::string_view text, size_t* pos, const ExprScope& scope, int depth) {
    if (depth > kMaxExprNesting) return Err(int(*pos) + 1, "statements nested deeper than 48");
    SkipSpace(text, pos);
    const size_t at = *pos;
    const int col = int(at) + 1;
    if (at >= text.size()) return Err(col, "expected a statement");
    const char c = text[at];
    if (c == ';') {
      ++*pos;
      return true;
    }
    if (c == '{') return Block(text, pos, scope, depth);
    if (Keyword(text, at, "if")) {
      *pos += 2;
      if (!Condition(text, pos, scope, "if")) return false;
      const size_t jumpElse = blockCode.size();
      Push(OpCode::kJumpIfZero, 0, col);
      if (!Statement(text, pos, scope, depth + 1)) return false;
      size_t q = *pos;
      SkipSpace(text, &q);
      if (Keyword(text, q, "else")) {
        *pos = q + 4;
        const size_t jumpEnd = blockCode.size();
        Push(OpCode::kJump, 0, col);
        blockCode[jumpElse].arg = uint32_t(blockCode.size());
        if (!Statement(text, pos, scope, depth + 1)) return false;
        blockCode[jumpEnd].arg = uint32_t(blockCode.size());
      } else {
        blockCode[jumpElse].arg = uint32_t(blockCode.size());
      }
      return true;
    }
    if (Keyword(text, at, "while")) {
      *pos += 5;
      const size_t top = blockCode.size();
      if (!Condition(text, pos, scope, "while")) return false;
      const size_t jumpEnd = blockCode.size();
      Push(OpCode::kJumpIfZero, 0, col);
      if (!Statement(text, pos, scope, depth + 1)) return false;
      Push(OpCode::kLoop, uint32_t(top), col);
      blockCode[jumpEnd].arg = uint32_t(blockCode.size());
      return true;
    }
    if (Keyword(text, at, "do")) {
      *pos += 2;
      const size_t top = blockCode.size();
      if (!Statement(text, pos, scope, depth + 1)) return false;
      SkipSpace(text, pos);
      if (!Keyword(text, *pos, "while")) return Err(int(*pos) + 1, "expected 'while' after 'do'");
      *pos += 5;
      if (!Condition(text, pos, scope, "while")) return false;
      // Loop while the condition holds: skip the loop-back when it is 0.
      const size_t jumpEnd = blockCode.size();
      Push(OpCode::kJumpIfZero, 0, col);
      Push(OpCode::kLoop, uint32_t(top), col);
      blockCode[jumpEnd].arg = uint32_t(blockCode.size());
      return EndOfStatement(text, pos);
    }
    if (!(std::isalpha(static_cast<unsigned char>(c)) || c == '_'))
      return Err(col, "expected a statement (an assignment 'name = expression;', if or while)");
    size_t e = at;
    while (e < text.size() && IsIdent(text[e])) ++e;
    const std::string name(text.substr(at, e - at));
    size_t q = e;
    SkipSpace(text, &q);
    if (q < text.size() && text[q] == '[') return ElementAssignment(text, pos, scope, name, col, q);
    if ((name == "srand" || name == "stop") && q < text.size() && text[q] == '(') {
      // cpfg's srand(seed) (reseed) and stop(v) (v other than 1 stops the
      // derivation): v is stored in a hidden global the derivation reads.
      const int slot = name == "srand" ? scope.srandSlot : scope.stopSlot;
      if (slot < 0)
        return Err(col, "'" + name + "(...)' belongs in a statement block", int(name.size()));
      *pos = q;
      if (!Expression(text, pos, scope)) return false;
      Push(OpCode::kStoreGlobal, uint32_t(slot), col);
      if (scope.writesGlobal) *scope.writesGlobal = true;  // in word order, as cpfg
      return EndOfStatement(text, pos);
    }
    if (name == "fscanf" && q < text.size() && text[q] == '(' && scope.dataFiles) {
      if (!Fscanf(text, q, pos, scope, col)) return false;
      Push(OpCode::kPop, 0, col);  // its count, unused
      return EndOfStatement(text, pos);
    }
    if (name == "fclose" && q < text.size() && text[q] == '(' && scope.dataFiles &&
        *scope.dataFiles && !(*scope.dataFiles)->empty()) {
      // Closes a file opened for reading (other values: nothing, as cpfg).
      *pos = q + 1;
      if (!Expression(text, pos, scope)) return false;
      SkipSpace(text, pos);
      if (*pos >= text.size() || text[*pos] != ')')
        return Err(int(*pos) + 1, "expected ')' after the file of 'fclose'");
      ++*pos;
      Push(OpCode::kFclose, 0, col);
      if (scope.writesGlobal) *scope.writesGlobal = true;  // files are read in word order
      return EndOfStatement(text, pos);
    }
    if (q < text.size() && text[q] == '(' && scope.outputCalls &&
        (name == "printf" || name == "fprintf" || name == "fclose" || name == "fflush")) {
      // cpfg's output: read, checked for balance, and compiled to nothing.
      if (!SkipCall(text, q, pos, name)) return false;
      const bool print = name == "printf" || name == "fprintf";
      scope.outputCalls->push_back(ExprParseError{
          col, int(name.size()),
          "'" + name + "(...)' " + (print ? "prints nothing" : "does nothing") +
              ": Sylva writes no output from a grammar (cpfg's printf, fprintf and files)"});
      return EndOfStatement(text, pos);
    }
    if (q < text.size() && text[q] == '(')
      return Err(col,
                 "a call '" + name + "(...)' as a statement is not supported (cpfg's printf, ...)",
                 int(name.size()));
    OpCode compound = OpCode::kConst;  // kConst: plain '='
    if (q + 1 < text.size() && text[q + 1] == '=' &&
        (text[q] == '+' || text[q] == '-' || text[q] == '*' || text[q] == '/')) {
      compound = text[q] == '+'   ? OpCode::kAdd
                 : text[q] == '-' ? OpCode::kSub
                 : text[q] == '*' ? OpCode::kMul
                                  : OpCode::kDiv;
      ++q;
    }
    if (q >= text.size() || text[q] != '=' || (q + 1 < text.size() && text[q + 1] == '='))
      return Err(int(q) + 1, "expected '=' after '" + name + "' (an assignment)");
    *pos = q + 1;
    // `f = fopen(NAME, "r")`: a data file read (cpfg_data_files.h);
    // `f = fopen(NAME, "w")`: cpfg's output file, not opened (f is 0);
    // `n = fscanf(...)`: its count.
    size_t f = *pos;
    SkipSpace(text, &f);
    bool fopenCall = false;
    if (compound == OpCode::kConst && scope.dataFiles && Keyword(text, f, "fopen")) {
      size_t paren = f + 5;
      SkipSpace(text, &paren);
      if (paren < text.size() && text[paren] == '(') {
        size_t a = paren + 1;
        std::string file, mode;
        int fileCol = 0, modeCol = 0;
        if (!StringArg(text, &a, &file, &fileCol))
          return Err(int(a) + 1, "expected the file name of 'fopen' in quotes");
        SkipSpace(text, &a);
        if (a >= text.size() || text[a] != ',') return Err(int(a) + 1, "expected ',' in 'fopen'");
        ++a;
        if (!StringArg(text, &a, &mode, &modeCol))
          return Err(int(a) + 1, "expected the mode of 'fopen' in quotes (\"r\" or \"w\")");
        SkipSpace(text, &a);
        if (a >= text.size() || text[a] != ')')
          return Err(int(a) + 1, "expected ')' after 'fopen'");
        if (!mode.empty() && mode[0] == 'r') {
          uint32_t id = 0;
          std::string why;
          if (!(*scope.dataFiles)->Add(UnescapeC(file), &id, &why)) return Err(fileCol, why);
          *pos = a + 1;
          Push(OpCode::kFopen, id, int(f) + 1);
          blockDepth = std::max(blockDepth, 1);
          if (scope.writesGlobal) *scope.writesGlobal = true;  // files are read in word order
          fopenCall = true;
        }
      }
    }
    if (!fopenCall && compound == OpCode::kConst && scope.dataFiles && Keyword(text, f, "fscanf")) {
      size_t paren = f + 6;
      SkipSpace(text, &paren);
      if (paren < text.size() && text[paren] == '(') {
        if (!Fscanf(text, paren, pos, scope, int(f) + 1)) return false;
        fopenCall = true;
      }
    }
    if (!fopenCall && compound == OpCode::kConst && scope.outputCalls &&
        Keyword(text, f, "fopen")) {
      size_t paren = f + 5;
      SkipSpace(text, &paren);
      if (paren < text.size() && text[paren] == '(') {
        const size_t open = paren;
        if (!SkipCall(text, paren, pos, "fopen")) return false;
        // The mode: the last "string" among the arguments.
        const std::string_view args = text.substr(open, *pos - open);
        const size_t close = args.rfind('"');
        const size_t start = close == std::string_view::npos || close == 0
                                 ? std::string_view::npos
                                 : args.rfind('"', close - 1);
        const std::string_view mode = start == std::string_view::npos
                                          ? std::string_view()
                                          : args.substr(start + 1, close - start - 1);
        if (mode.empty() || mode.find_first_of("r+") != std::string_view::npos)
          return Err(int(f) + 1,
                     "fopen for reading is not supported (cpfg's fopen with \"r\" and fscanf: "
                     "Sylva reads no data files from a grammar)",
                     5);
        scope.outputCalls->push_back(ExprParseError{
            int(f) + 1, 5,
            "'fopen(...)' opens no file: Sylva writes no output from a grammar (cpfg's printf, "
            "fprintf and files); '" +
                name + "' is 0"});
        Push(OpCode::kConst, 0, int(f) + 1);
        blockDepth = std::max(blockDepth, 1);
        fopenCall = true;
      }
    }
    // The target: a formal or local, a global, or a new local.
    uint32_t slot = 0;
    OpCode store = OpCode::kStore;
    bool found = Parser::FindVar(scope, name, &slot);
    if (!found && scope.globals) {
      for (size_t i = 0; i < scope.globals->size(); ++i) {
        if ((*scope.globals)[i] == name) {
          slot = uint32_t(i);
          store = OpCode::kStoreGlobal;
          found = true;
        }
      }
    }
    if (compound != OpCode::kConst && !found)
      return Err(col, "'" + name + "' has no value before this assignment", int(name.size()));
    if (compound != OpCode::kConst)
      Push(store == OpCode::kStore ? OpCode::kFormal : OpCode::kGlobal, slot, col);
    if (!fopenCall && !Expression(text, pos, scope)) return false;
    if (compound != OpCode::kConst) {
      Push(compound, 0, col);
      blockDepth = std::max(blockDepth, 2);
    }
    if (!found) {
      if (!scope.locals)
        return Err(col,
                   "'" + name +
                       "' is not a variable here (a global variable is one assigned in Start:, "
                       "StartEach:, EndEach: or End:)",
                   int(name.size()));
      // Declared after its value is compiled: `y = y + 1` with no y is an error.
      scope.locals->push_back(name);
      Parser::FindVar(scope, name, &slot);
    }
    if (store == OpCode::kStoreGlobal && scope.writesGlobal) *scope.writesGlobal = true;
    Push(store, slot, col);
    return EndOfStatement(text, pos);
  }

  // A "string" at *pos (blanks before it skipped): its body as written
  // (escapes kept) and the column of its opening quote; *pos past it.
  bool StringArg(std::string_view text, size_t* pos, std::string* body, int* column) {
    SkipSpace(text, pos);
    if (*pos >= text.size() || text[*pos] != '"') return false;
    *column = int(*pos) + 1;
    size_t i = *pos + 1;
    for (; i < text.size() && text[i] != '"'; ++i)
      if (text[i] == '\\') ++i;
    if (i >= text.size()) return false;
    *body = std::string(text.substr(*pos + 1, i - *pos - 1));
    *pos = i + 1;
    return true;
  }

  // One sub-expression emitted while `onStack` values are on the stack.
  bool ExpressionAbove(std::string_view text, size_t* pos, const ExprScope& scope, int onStack,
                       int* maxDepth) {
    const int saved = blockDepth;
    blockDepth = 0;
    if (!Expression(text, pos, scope)) return false;
    *maxDepth = std::max(*maxDepth, onStack + blockDepth);
    blockDepth = saved;
    return true;
  }

  // `fscanf(FP, "FORMAT", &x, &a[i], ...)` from text[open] == '(' (*pos is
  // set past its ')'): the handle, then each address's [offset and] value
  // on the stack, kFscanf, and the stores; fscanf's count is left on the
  // stack (cpfg_data_files.h).
  bool Fscanf(std::string_view text, size_t open, size_t* pos, const ExprScope& scope, int col) {
    int maxDepth = 0, onStack = 0;
    *pos = open + 1;
    if (!ExpressionAbove(text, pos, scope, 0, &maxDepth)) return false;
    onStack = 1;
    SkipSpace(text, pos);
    if (*pos >= text.size() || text[*pos] != ',')
      return Err(int(*pos) + 1, "expected ',' after the file of 'fscanf'");
    ++*pos;
    std::string body;
    int formatCol = 0;
    if (!StringArg(text, pos, &body, &formatCol))
      return Err(int(*pos) + 1, "expected the format of 'fscanf' in quotes");
    ScanFormat format;
    std::string why;
    if (!ParseScanFormat(UnescapeC(body), &format, &why))
      return Err(formatCol, "fscanf: " + why, int(body.size()) + 2);
    struct Target {
      OpCode store;
      uint32_t slot;
      bool element;
    };
    std::vector<Target> targets;
    for (;;) {
      SkipSpace(text, pos);
      if (*pos < text.size() && text[*pos] == ')') break;
      if (*pos >= text.size() || text[*pos] != ',')
        return Err(int(*pos) + 1, "expected ',' or ')' in 'fscanf'");
      ++*pos;
      SkipSpace(text, pos);
      if (*pos >= text.size() || text[*pos] != '&')
        return Err(int(*pos) + 1, "fscanf reads into variables: write '&name' or '&a[i]'");
      ++*pos;
      SkipSpace(text, pos);
      const size_t s = *pos;
      while (*pos < text.size() && IsIdent(text[*pos])) ++*pos;
      const std::string name(text.substr(s, *pos - s));
      const int tcol = int(s) + 1;
      if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0])))
        return Err(tcol, "expected a variable name after '&'");
      if (int(targets.size()) == kMaxScanValues)
        return Err(tcol - 1, "fscanf assigns at most 10 values (cpfg's limit)");
      size_t q = *pos;
      SkipSpace(text, &q);
      if (q < text.size() && text[q] == '[') {  // &a[i][j]
        const ArrayShape* a = nullptr;
        if (scope.arrays)
          for (const ArrayShape& x : *scope.arrays)
            if (x.name == name) a = &x;
        if (!a)
          return Err(tcol,
                     "'" + name + "' is not an array (arrays are declared in 'define: { array " +
                         name + "[n]; }')",
                     int(name.size()));
        Push(OpCode::kConst, 0, tcol);  // the offset, built one index at a time
        ++onStack;
        *pos = q;
        int dimension = 1;
        for (uint32_t d : a->dims) {
          SkipSpace(text, pos);
          if (*pos >= text.size() || text[*pos] != '[')
            return Err(int(*pos) + 1, "array '" + name + "' needs " +
                                          std::to_string(a->dims.size()) +
                                          (a->dims.size() == 1 ? " index" : " indices"));
          ++*pos;
          if (!ExpressionAbove(text, pos, scope, onStack, &maxDepth)) return false;
          SkipSpace(text, pos);
          if (*pos >= text.size() || text[*pos] != ']')
            return Err(int(*pos) + 1, "expected ']' after an index of '" + name + "'");
          ++*pos;
          Push(OpCode::kIndex, d, tcol);
          if (scope.indexSite) blockCode.back().value = scope.indexSite(tcol, *a, dimension);
          ++dimension;
        }
        SkipSpace(text, pos);
        if (*pos < text.size() && text[*pos] == '[')
          return Err(int(*pos) + 1, "array '" + name + "' has " + std::to_string(a->dims.size()) +
                                        (a->dims.size() == 1 ? " dimension" : " dimensions"));
        Push(OpCode::kDup, 0, tcol);
        Push(OpCode::kGlobalAt, a->base, tcol);
        ++onStack;
        maxDepth = std::max(maxDepth, onStack);
        targets.push_back(Target{OpCode::kStoreGlobalAt, a->base, true});
        continue;
      }
      uint32_t slot = 0;
      OpCode load = OpCode::kFormal, store = OpCode::kStore;
      bool found = Parser::FindVar(scope, name, &slot);
      if (!found && scope.globals) {
        for (size_t i = 0; i < scope.globals->size(); ++i) {
          if ((*scope.globals)[i] == name) {
            slot = uint32_t(i);
            load = OpCode::kGlobal;
            store = OpCode::kStoreGlobal;
            found = true;
          }
        }
      }
      if (!found) {
        if (!scope.locals)
          return Err(tcol,
                     "'" + name +
                         "' is not a variable here (a global variable is one assigned in Start:, "
                         "StartEach:, EndEach: or End:)",
                     int(name.size()));
        scope.locals->push_back(name);  // a new local, 0 until read
        Parser::FindVar(scope, name, &slot);
      }
      Push(load, slot, tcol);
      ++onStack;
      maxDepth = std::max(maxDepth, onStack);
      targets.push_back(Target{store, slot, false});
    }
    ++*pos;  // ')'
    if (int(targets.size()) != format.assignments)
      return Err(formatCol,
                 "fscanf: the format assigns " + std::to_string(format.assignments) +
                     (format.assignments == 1 ? " value" : " values") + " and " +
                     std::to_string(targets.size()) +
                     (targets.size() == 1 ? " address follows" : " addresses follow"),
                 int(body.size()) + 2);
    CpfgDataFiles::Call call;
    call.format = std::move(format);
    for (const Target& t : targets) call.element.push_back(t.element ? 1 : 0);
    Push(OpCode::kFscanf, (*scope.dataFiles)->AddCall(std::move(call)), col);
    for (size_t k = targets.size(); k-- > 0;) Push(targets[k].store, targets[k].slot, col);
    blockDepth = std::max(blockDepth, maxDepth + 1);     // kDup
    if (scope.writesGlobal) *scope.writesGlobal = true;  // files are read in word order
    return true;
  }

  // `a[i][j] = expr;` (text[q] is the first '[').
  bool ElementAssignment(std::string_view text, size_t* pos, const ExprScope& scope,
                         const std::string& name, int col, size_t q) {
    const ArrayShape* a = nullptr;
    if (scope.arrays)
      for (const ArrayShape& x : *scope.arrays)
        if (x.name == name) a = &x;
    if (!a)
      return Err(col,
                 "'" + name + "' is not an array (arrays are declared in 'define: { array " + name +
                     "[n]; }')",
                 int(name.size()));
    blockCode.push_back(Instr{OpCode::kConst, 0, 0});
    blockColumns.push_back(uint32_t(col));
    *pos = q;
    int dimension = 1;
    for (uint32_t d : a->dims) {
      SkipSpace(text, pos);
      if (*pos >= text.size() || text[*pos] != '[')
        return Err(int(*pos) + 1, "array '" + name + "' needs " + std::to_string(a->dims.size()) +
                                      (a->dims.size() == 1 ? " index" : " indices"));
      ++*pos;
      const int before = blockDepth;
      if (!Expression(text, pos, scope)) return false;
      blockDepth = std::max(before, blockDepth + 1);  // the offset so far is below it
      SkipSpace(text, pos);
      if (*pos >= text.size() || text[*pos] != ']')
        return Err(int(*pos) + 1, "expected ']' after an index of '" + name + "'");
      ++*pos;
      Push(OpCode::kIndex, d, col);
      if (scope.indexSite) blockCode.back().value = scope.indexSite(col, *a, dimension);
      ++dimension;
    }
    SkipSpace(text, pos);
    if (*pos < text.size() && text[*pos] == '[')
      return Err(int(*pos) + 1, "array '" + name + "' has " + std::to_string(a->dims.size()) +
                                    (a->dims.size() == 1 ? " dimension" : " dimensions"));
    if (*pos + 1 < text.size() && text[*pos + 1] == '=' && std::strchr("+-*/", text[*pos]))
      return Err(int(*pos) + 1,
                 "compound assignment to an array element is not supported: write '" + name +
                     "[...] = " + name + "[...] " + std::string(1, text[*pos]) + " ...'",
                 2);
    if (*pos >= text.size() || text[*pos] != '=' ||
        (*pos + 1 < text.size() && text[*pos + 1] == '='))
      return Err(int(*pos) + 1, "expected '=' after '" + name + "[...]' (an assignment)");
    ++*pos;
    const int before = blockDepth;
    blockDepth = 0;
    if (!Expression(text, pos, scope)) return false;
    blockDepth = std::max(before, blockDepth + 1);
    if (scope.writesGlobal) *scope.writesGlobal = true;
    Push(OpCode::kStoreGlobalAt, a->base, col);
    return EndOfStatement(text, pos);
  }

  ExprParseError* err_;
};

bool ParseBlock(std::string_view text, size_t* pos, const ExprScope& scope, Expr* out,
                ExprParseError* err) {
  ExprCompiler c(err);
  c.scope_ = &scope;
  if (!c.Block(text, pos, scope, 0)) return false;
  if (c.blockDepth + 1 >= Expr::kMaxStack) {
    err->column = int(*pos);
    err->message = "statement too complex (evaluation stack deeper than 64)";
    return false;
  }
  c.TakeBlock(out);
  return true;
}

bool IsStatementBlock(std::string_view text, size_t pos, std::string_view next) {
  auto isIdent = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  auto startsStatement = [&](std::string_view t, size_t p) {
    while (p < t.size() && (t[p] == ' ' || t[p] == '\t' || t[p] == '\r')) ++p;
    if (p >= t.size() || !(std::isalpha(static_cast<unsigned char>(t[p])) || t[p] == '_'))
      return false;
    size_t e = p;
    while (e < t.size() && isIdent(t[e])) ++e;
    const std::string_view word = t.substr(p, e - p);
    size_t q = e;
    while (q < t.size() && (t[q] == ' ' || t[q] == '\t')) ++q;
    if ((word == "if" || word == "while" || word == "printf" || word == "fprintf" ||
         word == "fclose" || word == "fflush" || word == "fscanf" || word == "srand" ||
         word == "stop") &&
        q < t.size() && t[q] == '(')
      return true;
    if (word == "do" && (q >= t.size() || t[q] == '{' || q > e)) return true;
    if (q < t.size() && t[q] == '[') {  // an array element: name[...] =
      while (q < t.size() && t[q] != ']') ++q;
      ++q;
      while (q < t.size() && (t[q] == ' ' || t[q] == '\t')) ++q;
    }
    if (q + 1 < t.size() && t[q + 1] == '=' &&
        std::string_view("+-*/").find(t[q]) != std::string_view::npos)
      return true;
    return q < t.size() && t[q] == '=' && (q + 1 >= t.size() || t[q + 1] != '=');
  };
  size_t p = pos + 1;
  while (p < text.size() && (text[p] == ' ' || text[p] == '\t' || text[p] == '\r')) ++p;
  if (p >= text.size()) return startsStatement(next, 0);
  return startsStatement(text, p);
}

bool ParseExpr(std::string_view text, size_t* pos, const ExprScope& scope, Expr* out,
               ExprParseError* err) {
  Parser p(text, *pos, scope, err);
  NodePtr root = p.Parse();
  if (!root) return false;
  *pos = p.pos();
  ExprCompiler c(err);
  c.scope_ = &scope;
  if (!c.Fold(*root)) return false;
  return c.Finish(*root, out);
}

}  // namespace sylva::lsys
