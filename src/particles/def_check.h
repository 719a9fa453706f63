// Checks for the particle library's definitions (internal): each returns a
// Diagnostic naming the field and the offending value, in the words of
// docs/design.md, "Bad numbers in definitions":
//   EmitterDef.rate 1e+30 is outside 0..1e+09 particles/s
// Every comparison is written so that NaN fails it, and a check that passes
// allocates nothing (fields are string views: the step checks run each step).
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

#include "core/math.h"
#include "core/status.h"

namespace sylva::particles::check {

inline std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// The parts one after another (appended, which spares GCC 12 its false
// -Wrestrict on chains of operator+).
template <typename... Parts>
std::string Cat(const Parts&... parts) {
  std::string s;
  (s.append(std::string_view(parts)), ...);
  return s;
}

inline std::string Vec(const Vec3& v) {
  return Cat("(", Num(v.x()), ", ", Num(v.y()), ", ", Num(v.z()), ")");
}

inline Diagnostic Error(std::string message) {
  Diagnostic d;
  d.message = std::move(message);
  return d;
}

// lo <= v <= hi (NaN and infinities outside any finite range).
inline Status Range(std::string_view field, double v, double lo, double hi, const char* unit = "") {
  if (v >= lo && v <= hi) return {};
  return Error(
      Cat(field, " ", Num(v), " is outside ", Num(lo), "..", Num(hi), *unit ? " " : "", unit));
}

// Every component finite and within [-limit, limit] (NaN hides in y and z
// too: each component is compared, never a norm or a maximum).
inline Status Finite(std::string_view field, const Vec3& v, double limit = 1e12,
                     const char* unit = "") {
  for (int k = 0; k < 3; ++k) {
    if (!(v[k] >= -limit && v[k] <= limit)) {
      return Error(Cat(field, " ", Vec(v), " has a component outside -", Num(limit), "..",
                       Num(limit), *unit ? " " : "", unit));
    }
  }
  return {};
}

inline Status Finite(std::string_view field, const Vec3f& v, double limit = 1e12,
                     const char* unit = "") {
  return Finite(field, Vec3(double(v.x()), double(v.y()), double(v.z())), limit, unit);
}

}  // namespace sylva::particles::check

// Returns the Status of `expr` when it is an error.
#define SYLVA_CHECK_OK(expr)      \
  do {                            \
    ::sylva::Status st_ = (expr); \
    if (!st_.ok()) return st_;    \
  } while (0)
