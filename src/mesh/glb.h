// The .glb container (glTF 2.0 spec, section 4.4): a 12-byte header, a JSON
// chunk padded with spaces, and a BIN chunk padded with zeros, written to a
// temporary file and renamed when complete (core/atomic_file.h). The BIN
// chunk is streamed: `emit` calls the sink with the buffer's bytes in
// order, in pieces, so a large buffer is never held twice.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "core/status.h"

namespace sylva::mesh {

using ByteSink = std::function<Status(const void* data, size_t bytes)>;

// `binBytes` is the buffer's length (0: no BIN chunk); `emit` must pass
// exactly that many bytes. `tooLarge` is the advice printed when the file
// would pass the format's 4 GiB limit.
Status WriteGlb(const std::string& path, std::string json, size_t binBytes,
                const std::function<Status(const ByteSink&)>& emit, const std::string& tooLarge);

}  // namespace sylva::mesh
