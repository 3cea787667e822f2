#include "formats/io/file_io.h"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string_view>

namespace zhc {

namespace fs = std::filesystem;

namespace {
std::atomic<FileRecorder*> g_recorder{nullptr};
void add_once(std::vector<std::string>& list, const std::string& path) {
    if (std::find(list.begin(), list.end(), path) == list.end()) list.push_back(path);
}
}  // namespace

void FileRecorder::add_input(const std::string& path) {
    std::lock_guard<std::mutex> lock(mutex_);
    add_once(inputs_, path);
}
void FileRecorder::add_output(const std::string& path) {
    std::lock_guard<std::mutex> lock(mutex_);
    add_once(outputs_, path);
}
std::vector<std::string> FileRecorder::inputs() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return inputs_;
}
std::vector<std::string> FileRecorder::outputs() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return outputs_;
}
ScopedFileRecording::ScopedFileRecording(FileRecorder* recorder) : previous_(g_recorder.exchange(recorder)) {}
ScopedFileRecording::~ScopedFileRecording() { g_recorder.store(previous_); }
void record_input(const std::string& path) {
    if (FileRecorder* r = g_recorder.load()) r->add_input(path);
}
void record_output(const std::string& path) {
    if (FileRecorder* r = g_recorder.load()) r->add_output(path);
}

Result<std::vector<std::uint8_t>> read_file_bytes(const std::string& path, std::uint64_t max_bytes) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st)) return make_error(ErrorCode::kIoError, path + ": no such file");
    if (fs::is_directory(st)) return make_error(ErrorCode::kIoError, path + ": is a directory, not a file");
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) return make_error(ErrorCode::kIoError, path + ": cannot open (" + std::strerror(errno) + ")");
    record_input(path);
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

bool looks_like_git_lfs_pointer(std::span<const std::uint8_t> bytes) {
    // The specification's first line ("version" key first). Decided from the first bytes alone, so
    // a reader that sees only a file's head (the streaming KTX2/DDS/EXR layout readers) answers as
    // one that sees the whole file.
    static constexpr std::string_view kPrefixes[] = {"version https://git-lfs.github.com/spec/", "version https://hawser.github.com/spec/"};
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    for (const std::string_view p : kPrefixes)
        if (text.substr(0, p.size()) == p) return true;
    return false;
}

std::string git_lfs_hint(std::span<const std::uint8_t> bytes) {
    return looks_like_git_lfs_pointer(bytes) ? "; it looks like a Git LFS pointer (the content was not fetched): run git lfs pull" : "";
}

Result<FilePrefix> read_file_prefix(const std::string& path, std::size_t max_bytes) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st)) return make_error(ErrorCode::kIoError, path + ": no such file");
    if (fs::is_directory(st)) return make_error(ErrorCode::kIoError, path + ": is a directory, not a file");
    if (!fs::is_regular_file(st)) return make_error(ErrorCode::kIoError, path + ": not a regular file");
    FilePrefix p;
    p.file_size = fs::file_size(path, ec);
    if (ec) return make_error(ErrorCode::kIoError, path + ": cannot read its size (" + ec.message() + ")");
    FileRangeReader r;
    if (Status s = r.open(path); !s) return s.error();
    p.bytes.resize(static_cast<size_t>(std::min<std::uint64_t>(p.file_size, max_bytes)));
    if (Status s = r.read(0, p.bytes.data(), p.bytes.size()); !s) return s.error();
    return p;
}

FileRangeReader::~FileRangeReader() {
    if (f_) std::fclose(f_);
}

Status FileRangeReader::open(const std::string& path) {
    if (f_) std::fclose(f_);
    path_ = path;
    f_ = std::fopen(path.c_str(), "rb");
    if (!f_) return make_error(ErrorCode::kIoError, path + ": cannot open (" + std::strerror(errno) + ")");
    record_input(path);
    return Ok{};
}

Status FileRangeReader::read(std::uint64_t offset, std::uint8_t* out, std::size_t size) {
    if (!f_) return make_error(ErrorCode::kInternal, path_ + ": not open");
    if (size == 0) return Ok{};
    if (offset > static_cast<std::uint64_t>(std::numeric_limits<off_t>::max()) ||
        ::fseeko(f_, static_cast<off_t>(offset), SEEK_SET) != 0)
        return make_error(ErrorCode::kIoError, path_ + ": cannot seek to byte " + std::to_string(offset));
    const size_t n = std::fread(out, 1, size, f_);
    if (n != size) {
        if (std::ferror(f_)) return make_error(ErrorCode::kIoError, path_ + ": read error");
        return make_error(ErrorCode::kTruncated, path_ + ": file ends at byte " + std::to_string(offset + n) + ", expected " +
                                                     std::to_string(offset + size) + " (changed while being read?)");
    }
    return Ok{};
}

namespace {
// The temporary files alive now, for the signal handler: fixed slots of static storage (the handler
// may touch nothing else: no allocation, no locks). A slot's state is kFree, kBusy (held for a moment
// by a normal thread that fills, compares or empties it: the handler skips it) or kLive (path holds
// a NUL-terminated name).
// A name that does not fit, or a registration when every slot is live, is not tracked: that
// temporary is still removed on every normal path, only not on a signal.
constexpr int kFree = 0, kBusy = 1, kLive = 2;
constexpr std::size_t kTemporarySlots = 128, kTemporaryPathBytes = 4096;
struct TemporarySlot {
    std::atomic<int> state{kFree};
    char path[kTemporaryPathBytes];
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads the slot states");
TemporarySlot g_temporaries[kTemporarySlots];

void register_temporary(const std::string& path) {
    if (path.size() >= kTemporaryPathBytes) return;
    for (TemporarySlot& slot : g_temporaries) {
        int expected = kFree;
        if (!slot.state.compare_exchange_strong(expected, kBusy)) continue;
        std::memcpy(slot.path, path.c_str(), path.size() + 1);
        slot.state.store(kLive);
        return;
    }
}

// Threads renaming temporaries over their final names now. A set of files is published whole or
// not at all: the publishing thread blocks the three signals for its renames, and a handler running
// on another thread waits for them to end before it removes anything.
std::atomic<int> g_publishing{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads the count");

class Publishing {
public:
    Publishing() {
        sigset_t block;
        ::sigemptyset(&block);
        for (const int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaddset(&block, sig);
        ::pthread_sigmask(SIG_BLOCK, &block, &previous_);
        g_publishing.fetch_add(1);
    }
    ~Publishing() {
        g_publishing.fetch_sub(1);
        ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr);  // a signal that came meanwhile is handled now
    }
    Publishing(const Publishing&) = delete;
    Publishing& operator=(const Publishing&) = delete;

private:
    sigset_t previous_;
};

extern "C" void remove_temporaries_and_reraise(int sig) {
    // Async-signal-safe only: atomic loads, nanosleep, unlink, sigaction, raise. A temporary
    // already renamed over its final name is gone under its temporary name: unlink fails and the
    // output stays.
    const int saved_errno = errno;
    while (g_publishing.load() > 0) {  // renames on another thread (never this one: it blocks us)
        struct timespec ms = {0, 1000000};
        ::nanosleep(&ms, nullptr);
    }
    for (TemporarySlot& slot : g_temporaries)
        if (slot.state.load() == kLive) ::unlink(slot.path);
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    ::sigemptyset(&dfl.sa_mask);
    ::sigaction(sig, &dfl, nullptr);
    errno = saved_errno;
    ::raise(sig);  // the default action: the process ends by this signal, as without the handler
}

std::string temporary_name_for(const std::string& path) {
    std::random_device rd;
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, ".tmp-%d-%08x", static_cast<int>(::getpid()), rd());
    const std::string name = path + suffix;
    register_temporary(name);
    return name;
}
}  // namespace

void release_temporary_path(const std::string& path) {
    if (path.size() >= kTemporaryPathBytes) return;  // never registered
    for (TemporarySlot& slot : g_temporaries) {
        // Hold the slot (kBusy) while comparing: another thread may release and refill it.
        int expected = kLive;
        if (!slot.state.compare_exchange_strong(expected, kBusy)) continue;
        const bool mine = std::strcmp(slot.path, path.c_str()) == 0;
        slot.state.store(mine ? kFree : kLive);
        if (mine) return;
    }
}

void remove_temporaries_on_signals() {
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
        struct sigaction old {};
        if (::sigaction(sig, nullptr, &old) != 0) continue;
        // A signal the process was started ignoring (nohup, a background job's SIGINT) stays ignored,
        // and a handler someone else installed stays theirs.
        if ((old.sa_flags & SA_SIGINFO) || old.sa_handler != SIG_DFL) continue;
        struct sigaction sa {};
        sa.sa_handler = remove_temporaries_and_reraise;
        ::sigemptyset(&sa.sa_mask);
        for (const int other : {SIGINT, SIGTERM, SIGHUP}) ::sigaddset(&sa.sa_mask, other);  // one cleanup at a time
        ::sigaction(sig, &sa, nullptr);
    }
}

Status write_via_temporary(const std::string& path, const std::function<Status(const std::string&)>& writer) {
    const std::string tmp = temporary_name_for(path);
    Status st = writer(tmp);
    std::error_code ec;
    if (!st) {
        fs::remove(tmp, ec);
        release_temporary_path(tmp);
        return st;
    }
    {
        const Publishing publishing;
        fs::rename(tmp, path, ec);
        if (ec) {
            const std::string why = ec.message();
            fs::remove(tmp, ec);
            release_temporary_path(tmp);
            return make_error(ErrorCode::kIoError, path + ": cannot write (" + why + ")");
        }
        release_temporary_path(tmp);
    }
    record_output(path);
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

AtomicFileSet::~AtomicFileSet() { discard(); }

void AtomicFileSet::discard() {
    for (std::FILE* f : files_)
        if (f) std::fclose(f);
    files_.clear();
    std::error_code ec;
    for (const auto& t : temps_) {
        fs::remove(t, ec);
        release_temporary_path(t);
    }
    temps_.clear();
    paths_.clear();
    written_.clear();
}

Status AtomicFileSet::open(const std::vector<std::string>& paths) {
    discard();
    for (const auto& path : paths) {
        temps_.push_back(temporary_name_for(path));
        paths_.push_back(path);
        written_.push_back(0);
        std::FILE* f = std::fopen(temps_.back().c_str(), "wb");
        if (!f) {
            const Error e = make_error(ErrorCode::kIoError, path + ": cannot create (" + std::strerror(errno) + ")");
            release_temporary_path(temps_.back());
            temps_.pop_back();  // never created
            discard();
            return e;
        }
        files_.push_back(f);
    }
    return Ok{};
}

Status AtomicFileSet::write(std::size_t file, const std::uint8_t* data, std::size_t size) {
    if (file >= files_.size() || !files_[file]) return make_error(ErrorCode::kInternal, "AtomicFileSet: write to a file not open");
    if (size > 0 && std::fwrite(data, 1, size, files_[file]) != size) {
        const Error e = make_error(ErrorCode::kIoError, paths_[file] + ": write failed");
        discard();
        return e;
    }
    written_[file] += size;
    return Ok{};
}

Status AtomicFileSet::commit() {
    for (size_t i = 0; i < files_.size(); ++i) {
        const bool flushed = std::fflush(files_[i]) == 0;
        const bool closed = std::fclose(files_[i]) == 0;
        files_[i] = nullptr;
        if (!flushed || !closed) {
            const Error e = make_error(ErrorCode::kIoError, paths_[i] + ": write failed");
            discard();
            return e;
        }
    }
    std::error_code ec;
    // A directory in the way would only show at the rename; look first so that the common case
    // fails before anything is replaced.
    for (const auto& path : paths_)
        if (fs::is_directory(path, ec)) {
            const Error e = make_error(ErrorCode::kIoError, path + ": is a directory");
            discard();
            return e;
        }
    const Publishing publishing;  // until the set is renamed (or rolled back) and released
    std::vector<std::string> renamed;
    for (size_t i = 0; i < paths_.size(); ++i) {
        std::error_code rec;
        fs::rename(temps_[i], paths_[i], rec);
        if (rec) {
            const Error e = make_error(ErrorCode::kIoError, paths_[i] + ": cannot write (" + rec.message() + ")");
            for (const auto& p : renamed) fs::remove(p, ec);
            discard();  // removes the temporaries not renamed yet (and tries the renamed names: gone)
            return e;
        }
        renamed.push_back(paths_[i]);
    }
    for (const auto& path : paths_) record_output(path);
    for (const auto& t : temps_) release_temporary_path(t);
    files_.clear();
    temps_.clear();
    paths_.clear();
    written_.clear();
    return Ok{};
}

Status write_files_atomic(const std::vector<std::pair<std::string, std::vector<std::uint8_t>>>& files) {
    std::vector<std::string> paths;
    for (const auto& f : files) paths.push_back(f.first);
    AtomicFileSet set;
    if (Status s = set.open(paths); !s) return s;
    for (size_t i = 0; i < files.size(); ++i)
        if (Status s = set.write(i, files[i].second.data(), files[i].second.size()); !s) return s;
    return set.commit();
}

std::string temporary_path_for(const std::string& path) { return temporary_name_for(path); }

Status check_folder_takes_files(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    const std::string folder = (parent.empty() ? fs::path(".") : parent).string();
    const std::string tmp = temporary_name_for(path);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    const int err = errno;
    if (fd >= 0) {
        ::close(fd);
        ::unlink(tmp.c_str());
    }
    release_temporary_path(tmp);
    if (fd >= 0) return Ok{};
    std::error_code ec;
    if (!fs::exists(folder, ec)) return make_error(ErrorCode::kIoError, "the folder " + folder + " does not exist");
    if (!fs::is_directory(folder, ec)) return make_error(ErrorCode::kIoError, folder + " is not a folder");
    return make_error(ErrorCode::kIoError, "cannot create a file in the folder " + folder + " (" + std::strerror(err) + ")");
}

std::string file_extension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

}  // namespace zhc
