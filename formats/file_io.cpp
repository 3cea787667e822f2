#include "file_io.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

namespace zhc {

namespace fs = std::filesystem;

Result<std::vector<std::uint8_t>> read_file_bytes(const std::string& path, std::uint64_t max_bytes) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st)) return make_error(ErrorCode::kIoError, path + ": no such file");
    if (fs::is_directory(st)) return make_error(ErrorCode::kIoError, path + ": is a directory, not a file");
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return make_error(ErrorCode::kIoError, path + ": cannot open (" + std::strerror(errno) + ")");
    std::vector<std::uint8_t> bytes;
    // Read in chunks: works for pipes and special files whose size is unknown, and never
    // allocates more than max_bytes + one chunk.
    std::uint8_t chunk[1 << 16];
    for (;;) {
        const size_t n = std::fread(chunk, 1, sizeof chunk, f);
        if (n > 0) {
            if (bytes.size() + n > max_bytes) {
                std::fclose(f);
                return make_error(ErrorCode::kTooLarge, path + ": file larger than the limit of " +
                                                            std::to_string(max_bytes) + " bytes");
            }
            bytes.insert(bytes.end(), chunk, chunk + n);
        }
        if (n < sizeof chunk) break;
    }
    const bool failed = std::ferror(f) != 0;
    std::fclose(f);
    if (failed) return make_error(ErrorCode::kIoError, path + ": read error");
    return bytes;
}

namespace {
std::string temporary_name_for(const std::string& path) {
    std::random_device rd;
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, ".tmp-%d-%08x", static_cast<int>(::getpid()), rd());
    return path + suffix;
}
}  // namespace

Status write_via_temporary(const std::string& path, const std::function<Status(const std::string&)>& writer) {
    const std::string tmp = temporary_name_for(path);
    Status st = writer(tmp);
    std::error_code ec;
    if (!st) {
        fs::remove(tmp, ec);
        return st;
    }
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        return make_error(ErrorCode::kIoError, path + ": cannot write (" + ec.message() + ")");
    }
    return Ok{};
}

namespace {
// Writes `bytes` to the temporary file `tmp` (messages name `path`, the file the user asked for).
// On failure `tmp` may exist; the caller removes it.
Status write_temporary(const std::string& tmp, const std::string& path, const std::vector<std::uint8_t>& bytes) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) return make_error(ErrorCode::kIoError, path + ": cannot create (" + std::strerror(errno) + ")");
    const bool ok = bytes.empty() || std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const bool flushed = std::fflush(f) == 0;
    const bool closed = std::fclose(f) == 0;
    if (!ok || !flushed || !closed) return make_error(ErrorCode::kIoError, path + ": write failed");
    return Ok{};
}
}  // namespace

Status write_file_atomic(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    return write_via_temporary(path, [&](const std::string& tmp) { return write_temporary(tmp, path, bytes); });
}

Status write_files_atomic(const std::vector<std::pair<std::string, std::vector<std::uint8_t>>>& files) {
    std::vector<std::string> temps;
    std::error_code ec;
    auto remove_all = [&](const std::vector<std::string>& paths) {
        for (const auto& p : paths) fs::remove(p, ec);
    };
    for (const auto& [path, bytes] : files) {
        temps.push_back(temporary_name_for(path));
        if (Status st = write_temporary(temps.back(), path, bytes); !st) {
            remove_all(temps);
            return st;
        }
    }
    // A directory in the way would only show at the rename; look first so that the common case
    // fails before anything is replaced.
    for (const auto& [path, bytes] : files)
        if (fs::is_directory(path, ec)) {
            remove_all(temps);
            return make_error(ErrorCode::kIoError, path + ": is a directory");
        }
    std::vector<std::string> renamed;
    for (size_t i = 0; i < files.size(); ++i) {
        std::error_code rec;
        fs::rename(temps[i], files[i].first, rec);
        if (rec) {
            remove_all(std::vector<std::string>(temps.begin() + static_cast<std::ptrdiff_t>(i), temps.end()));
            remove_all(renamed);
            return make_error(ErrorCode::kIoError, files[i].first + ": cannot write (" + rec.message() + ")");
        }
        renamed.push_back(files[i].first);
    }
    return Ok{};
}

std::string file_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

}  // namespace zhc
