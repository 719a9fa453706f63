#include "lsys/unsupported.h"

namespace sylva::lsys {

namespace {

struct Command {
  std::string_view name;
  std::string_view what;  // cpfg's meaning, as its manual names it
};

// cpfg's @ commands that Sylva lexes but does not draw.
constexpr Command kUndrawn[] = {
    {"@PS", "bicubic patch"},       {"@PD", "bicubic patch"}, {"@Sx", "surface command"},
    {"@m", "move-to with drawing"}, {"@D", "scale factor"},   {"@i", "interpolation"},
    {"@b", "bounding box"},         {"@Tx", "texture"},       {"@;", "back-side colour"},
};

std::string Params(int n) {
  return std::to_string(n) + (n == 1 ? " parameter" : " parameters");
}

}  // namespace

std::optional<std::string> UnsupportedModule(std::string_view name, int arity) {
  if (name.empty()) return std::nullopt;
  if (name[0] == '@') {
    if (name == "@O") {
      if (arity <= 1) return std::nullopt;
      return "'@O' (sphere) uses 1 parameter, the diameter; the other " +
             std::to_string(arity - 1) + " are ignored";
    }
    // Implemented, with the parameters they use (docs/turtle.md).
    struct Used {
      std::string_view name, what, params;
      int most;
    };
    static constexpr Used kUsed[] = {
        {"@o", "disc", "the diameter", 1},
        {"@c", "circle", "the diameter", 1},
        {"@v", "roll to vertical", "none", 0},
        {"@Gs", "start of a generalized cylinder", "none", 0},
        {"@Gc", "generalized cylinder point", "the number of segments", 1},
        {"@Ge", "end of a generalized cylinder", "the number of segments", 1},
        {"@Gt", "generalized cylinder tangents", "the arriving and leaving factors", 2},
        {"@Gr", "generalized cylinder radius tangents", "4 (angle, length, angle, length)", 4},
        {"@Ts", "set tropism elasticity", "the tropism and the elasticity", 2},
        {"@Ti", "raise tropism elasticity", "the tropism and the step", 2},
        {"@Td", "lower tropism elasticity", "the tropism and the step", 2},
        {"@Tf", "keep the twist", "none", 0},
        {"@#", "generalized cylinder contour", "the contour's id", 1},
        {"@!", "sides of a generalized cylinder's contour", "the number of sides", 1},
        {"@L", "label", "a text and the numbers it formats", 1 << 20},
    };
    if (name == "@Gr" && arity == 3) {
      return std::string(
          "'@Gr' (generalized cylinder radius tangents) with 3 parameters: the "
          "third is ignored (a second tangent takes 2, angle and length)");
    }
    for (const Used& u : kUsed) {
      if (name != u.name) continue;
      if (arity <= u.most) return std::nullopt;
      return "'" + std::string(name) + "' (" + std::string(u.what) + ") uses " +
             (u.most == 0 ? std::string("no parameters") : std::string(u.params)) + "; the other " +
             std::to_string(arity - u.most) + " are ignored";
    }
    if (name == "@R") {
      // blackbox.c 'R': 2 (z = 0), 3, or 6 with the up vector.
      if (arity == 2 || arity == 3 || arity == 6) return std::nullopt;
      if (arity < 2) {
        return "'@R' (set the heading) needs 2 parameters (x, y), 3 (x, y, z) or 6 (the "
               "heading and the up vector); with " +
               Params(arity) + " it does nothing";
      }
      if (arity < 6) {
        return "'@R' (set the heading) uses 3 parameters for the heading, or 6 with the up "
               "vector; of its " +
               Params(arity) + ", the last " + std::to_string(arity - 3) + " are ignored";
      }
      return "'@R' (set the heading and up vector) uses 6 parameters; the other " +
             std::to_string(arity - 6) + " are ignored";
    }
    if (name == "@M") {
      if (arity == 3) return std::nullopt;
      return "'@M' (move to) needs 3 parameters (x, y, z); with " + Params(arity) +
             " it does nothing";
    }
    for (const Command& c : kUndrawn) {
      if (name == c.name) {
        return "'" + std::string(name) + "' (cpfg: " + std::string(c.what) +
               ") is not implemented in Sylva: it does nothing";
      }
    }
    return "'" + std::string(name) + "' is not a command Sylva knows: it does nothing";
  }
  if (name == "_" && arity > 1) {
    return "'_' (cpfg: set the tropism elasticity) uses 1 parameter; the other " +
           std::to_string(arity - 1) + " are ignored";
  }
  // cpfg interpret.c: `{(type, rings)` and `}(type)` with type != 0 start and
  // end a spline (general.c InitializeSpline); the turtle draws them.
  if (name == "{" && arity > 2) {
    return "'{' (a polygon, or with a type other than 0 a spline) uses 2 parameters, the type "
           "and the rings per piece; the other " +
           std::to_string(arity - 2) + " are ignored";
  }
  if (name == "}" && arity > 1) {
    return "'}' (the end of a polygon, or with a parameter other than 0 of a spline) uses 1 "
           "parameter; the other " +
           std::to_string(arity - 1) + " are ignored";
  }
  if (name == "$" && arity > 0) {
    // Some files write $(id, scale) for the start of a sub-L-system; cpfg's
    // source (generate.c CheckPred, interpret.c UpdateCurrentLsystem) starts
    // one only at ?(id, scale) and ends one at any $.
    return "'$' takes no parameters; here it has " + Params(arity) +
           ", ignored ('$' ends a sub-L-system, or rolls the turtle horizontal; a "
           "sub-L-system starts with ?(id, scale))";
  }
  if (name == "?") {  // ?(id, scale): the start of a sub-L-system
    if (arity == 1 || arity == 2) return std::nullopt;
    return "'?' (start of a sub-L-system) uses 2 parameters, the L-system's number and the "
           "scale; the other " +
           std::to_string(arity - 2) + " are ignored";
  }
  if (name[0] == '?') {
    // ?P ?H ?L ?U are answered after each step (plant::Grower): 2 parameters
    // take x, y and 3 take x, y, z. ?E is answered by the grammar's
    // `environment:` (the parser warns when there is none).
    if (name == "?P" || name == "?H" || name == "?L" || name == "?U") {
      if (arity == 2 || arity == 3) return std::nullopt;
      return "query module '" + std::string(name) +
             "' takes 2 parameters (x, y) or 3 (x, y, z); with " + Params(arity) +
             " it is not answered: its parameters keep the values written in the grammar";
    }
    if (name == "?E") {
      if (arity >= 1) return std::nullopt;
      return "query module '?E' needs at least 1 parameter for the environment to fill; with "
             "none it is not answered";
    }
    return "query module '" + std::string(name) +
           "' is not answered (Sylva answers ?P ?H ?L ?U and ?E): its parameters keep the "
           "values written in the grammar";
  }
  if (name[0] == '~') {
    if (arity <= 1 || arity == 3) return std::nullopt;
    return "surface '" + std::string(name) + "' takes 1 scale or 3 (x, y, z); of its " +
           Params(arity) +
           (arity == 2 ? " only the first (a uniform scale) is used" : " the first 3 are used");
  }
  return std::nullopt;
}

}  // namespace sylva::lsys
