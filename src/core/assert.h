// Programmer-error checks. Input errors never go through here: they travel
// as Diagnostic values (see status.h).
//   SYLVA_ASSERT(cond)  always on, aborts with file:line and the condition.
//   SYLVA_DCHECK(cond)  debug builds only.
#pragma once

namespace sylva::detail {
[[noreturn]] void AssertFail(const char* cond, const char* file, int line);
}

#define SYLVA_ASSERT(cond) \
  ((cond) ? (void)0 : ::sylva::detail::AssertFail(#cond, __FILE__, __LINE__))

#ifdef NDEBUG
#define SYLVA_DCHECK(cond) ((void)0)
#else
#define SYLVA_DCHECK(cond) SYLVA_ASSERT(cond)
#endif
