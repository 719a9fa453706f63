// libFuzzer target: any bytes as a Wavefront OBJ surface (`~name`), read by
// the OBJ reader. Must never crash, hang or leak; a mesh it returns must
// index only its own vertices.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "mesh/obj_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto m = sylva::mesh::ParseObj(text, "fuzz.obj");
  if (!m) {
    (void)m.error().Format();
    return 0;
  }
  for (uint32_t i : m->indices) {
    if (i >= m->positions.size()) std::abort();
  }
  return 0;
}
