// Memory helpers for large arrays.
#pragma once

#include <cstddef>

namespace sylva {

// Asks the kernel to back [p, p + bytes) with transparent huge pages where
// the range covers whole 2 MiB pages (Linux; a no-op elsewhere). Call it on
// a freshly reserved buffer before writing it: a 100 MB array then takes
// about 50 page faults instead of 25,000.
void AdviseHugePages(void* p, size_t bytes);

}  // namespace sylva
