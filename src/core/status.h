// Status and Expected<T>: how input errors travel. No exception crosses a
// library boundary; a function that can fail on user input returns one of
// these, carrying the Diagnostic that explains why.
#pragma once

#include <optional>
#include <utility>
#include <variant>

#include "core/assert.h"
#include "core/diagnostic.h"

namespace sylva {

class [[nodiscard]] Status {
 public:
  Status() = default;                             // success
  Status(Diagnostic d) : error_(std::move(d)) {}  // NOLINT: implicit on purpose

  bool ok() const { return !error_.has_value(); }
  explicit operator bool() const { return ok(); }
  const Diagnostic& error() const {
    SYLVA_ASSERT(error_.has_value());
    return *error_;
  }

 private:
  std::optional<Diagnostic> error_;
};

template <typename T>
class [[nodiscard]] Expected {
 public:
  Expected(T value) : v_(std::move(value)) {}           // NOLINT
  Expected(Diagnostic error) : v_(std::move(error)) {}  // NOLINT

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  T& value() & {
    SYLVA_ASSERT(ok());
    return std::get<0>(v_);
  }
  const T& value() const& {
    SYLVA_ASSERT(ok());
    return std::get<0>(v_);
  }
  T&& value() && {
    SYLVA_ASSERT(ok());
    return std::get<0>(std::move(v_));
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  const Diagnostic& error() const {
    SYLVA_ASSERT(!ok());
    return std::get<1>(v_);
  }

 private:
  std::variant<T, Diagnostic> v_;
};

}  // namespace sylva
