// zhc/formats/file_io.h — bounded file reads and atomic file writes.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "codec/status.h"

namespace zhc {

// Whole file into memory; fails with kTooLarge (before allocating) when it exceeds max_bytes.
Result<std::vector<std::uint8_t>> read_file_bytes(const std::string& path, std::uint64_t max_bytes);

// Writes `bytes` to `path` atomically: a temporary file in the same folder, flushed, then renamed
// over `path`. On failure `path` is untouched and no temporary file is left behind.
Status write_file_atomic(const std::string& path, const std::vector<std::uint8_t>& bytes);

// Writes several files as one unit: every file goes to a temporary name first; only when all of
// them are written are they renamed over their paths. If any write fails, no path is touched and
// no temporary file is left behind. If a rename fails (e.g. a directory of that name), the files
// already renamed in this call are removed again, so the set is never left half new.
Status write_files_atomic(const std::vector<std::pair<std::string, std::vector<std::uint8_t>>>& files);

// For libraries that write to a file name themselves: `writer` writes to the temporary name it
// is given; on success that file is renamed over `path`, on failure it is removed.
Status write_via_temporary(const std::string& path, const std::function<Status(const std::string&)>& writer);

// Lower-case extension including the dot ("" when none): "a/b.EXR" -> ".exr".
std::string file_extension(const std::string& path);

}  // namespace zhc
