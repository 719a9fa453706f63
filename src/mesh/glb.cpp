#include "mesh/glb.h"

#include <cstdint>

#include "core/assert.h"
#include "core/atomic_file.h"

namespace sylva::mesh {

Status WriteGlb(const std::string& path, std::string json, size_t binBytes,
                const std::function<Status(const ByteSink&)>& emit, const std::string& tooLarge) {
  while (json.size() % 4) json += ' ';
  const size_t bin = (binBytes + 3) / 4 * 4;
  const uint64_t length = 12 + 8 + json.size() + (binBytes ? 8 + bin : 0);
  if (length > 0xFFFFFFFFull) {
    Diagnostic d;
    d.kind = ErrorKind::kRuntime;
    d.loc.file = path;
    d.message = tooLarge;
    return d;
  }
  AtomicFile f;
  if (Status s = f.Open(path); !s.ok()) return s;
  auto u32 = [&](uint32_t v) { return f.Write(&v, 4); };
  if (Status s = u32(0x46546C67u); !s.ok()) return s;  // "glTF"
  if (Status s = u32(2); !s.ok()) return s;
  if (Status s = u32(uint32_t(length)); !s.ok()) return s;
  if (Status s = u32(uint32_t(json.size())); !s.ok()) return s;
  if (Status s = u32(0x4E4F534Au); !s.ok()) return s;  // "JSON"
  if (Status s = f.Write(json); !s.ok()) return s;
  if (binBytes > 0) {
    if (Status s = u32(uint32_t(bin)); !s.ok()) return s;
    if (Status s = u32(0x004E4942u); !s.ok()) return s;  // "BIN\0"
    size_t written = 0;
    const ByteSink sink = [&](const void* p, size_t n) {
      written += n;
      return f.Write(p, n);
    };
    if (Status s = emit(sink); !s.ok()) return s;
    SYLVA_ASSERT(written == binBytes);
    static const char zeros[4] = {0, 0, 0, 0};
    if (Status s = f.Write(zeros, bin - binBytes); !s.ok()) return s;
  }
  return f.Commit();
}

}  // namespace sylva::mesh
