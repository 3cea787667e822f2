// zhc/formats/file_io.h — bounded file reads and atomic file writes.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "codec/status.h"

namespace zhc {

// Whole file into memory; fails with kTooLarge (before allocating) when it exceeds max_bytes.
Result<std::vector<std::uint8_t>> read_file_bytes(const std::string& path, std::uint64_t max_bytes);

// Writes `bytes` to `path` atomically: a temporary file in the same folder, flushed, then renamed
// over `path`. On failure `path` is untouched and no temporary file is left behind.
Status write_file_atomic(const std::string& path, const std::vector<std::uint8_t>& bytes);

// For libraries that write to a file name themselves: `writer` writes to the temporary name it
// is given; on success that file is renamed over `path`, on failure it is removed.
Status write_via_temporary(const std::string& path, const std::function<Status(const std::string&)>& writer);

// Lower-case extension including the dot ("" when none): "a/b.EXR" -> ".exr".
std::string file_extension(const std::string& path);

}  // namespace zhc
