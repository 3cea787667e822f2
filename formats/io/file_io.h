// zhc/formats/io/file_io.h — bounded file reads and atomic file writes.
//
// Thread safety (docs/api.md): every function here is reentrant; calls may run concurrently
// on different files and arguments. The process-wide state is the FileRecorder that a
// ScopedFileRecording installs (below): it observes which files are opened and written, under its
// own lock, and never changes what a call does (there is one recorder per process, so run one
// recording at a time: two concurrent recordings would each see the other's files); and the table
// of live temporary names that remove_temporaries_on_signals' handler removes (lock-free slots).
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "codec/status.h"

namespace zhc {

// Whole file into memory; fails with kTooLarge (before allocating) when it exceeds max_bytes.
Result<std::vector<std::uint8_t>> read_file_bytes(const std::string& path, std::uint64_t max_bytes);

// A Git LFS pointer: the short text file ("version https://git-lfs.github.com/spec/v1", then oid
// and size lines) a checkout holds in place of a file whose content Git LFS did not fetch.
bool looks_like_git_lfs_pointer(std::span<const std::uint8_t> bytes);
// "; it looks like a Git LFS pointer (the content was not fetched): run git lfs pull" for such
// bytes, else "": appended to the messages of readers that did not recognise a file.
std::string git_lfs_hint(std::span<const std::uint8_t> bytes);

// The first min(size, max_bytes) bytes of a regular file, and its size (streaming readers check
// a header first and read the rest piece by piece). Not for pipes: fails kIoError.
struct FilePrefix {
    std::vector<std::uint8_t> bytes;
    std::uint64_t file_size = 0;
};
Result<FilePrefix> read_file_prefix(const std::string& path, std::size_t max_bytes);

// Reads byte ranges of a file (streaming readers). Errors name the file; a range past the end is
// kTruncated (the file changed after its header was checked).
class FileRangeReader {
public:
    FileRangeReader() = default;
    FileRangeReader(const FileRangeReader&) = delete;
    FileRangeReader& operator=(const FileRangeReader&) = delete;
    ~FileRangeReader();
    Status open(const std::string& path);
    Status read(std::uint64_t offset, std::uint8_t* out, std::size_t size);

private:
    std::string path_;
    std::FILE* f_ = nullptr;
};

// Writes `bytes` to `path` atomically: a temporary file in the same folder, flushed, then renamed
// over `path`. On failure `path` is untouched and no temporary file is left behind.
Status write_file_atomic(const std::string& path, const std::vector<std::uint8_t>& bytes);

// Writes several files as one unit: every file goes to a temporary name first; only when all of
// them are written are they renamed over their paths. If any write fails, no path is touched and
// no temporary file is left behind. If a rename fails (e.g. a directory of that name), the files
// already renamed in this call are removed again, so the set is never left half new.
Status write_files_atomic(const std::vector<std::pair<std::string, std::vector<std::uint8_t>>>& files);

// Several files written piece by piece (streaming) and published as one unit, like
// write_files_atomic: open() creates a temporary file per path; write() appends to one of them;
// commit() flushes and closes them and renames them over their paths (all or none, with the same
// roll-back as write_files_atomic). Until commit() succeeds no path is touched; the destructor (or
// a failed write/commit) removes every temporary file.
class AtomicFileSet {
public:
    AtomicFileSet() = default;
    AtomicFileSet(const AtomicFileSet&) = delete;
    AtomicFileSet& operator=(const AtomicFileSet&) = delete;
    ~AtomicFileSet();
    Status open(const std::vector<std::string>& paths);
    Status write(std::size_t file, const std::uint8_t* data, std::size_t size);
    Status commit();
    // Bytes written so far to `file`.
    std::uint64_t written(std::size_t file) const { return file < written_.size() ? written_[file] : 0; }

private:
    void discard();
    std::vector<std::string> paths_, temps_;
    std::vector<std::FILE*> files_;
    std::vector<std::uint64_t> written_;
};

// For libraries that write to a file name themselves: `writer` writes to the temporary name it
// is given; on success that file is renamed over `path`, on failure it is removed.
Status write_via_temporary(const std::string& path, const std::function<Status(const std::string&)>& writer);

// A fresh temporary name next to `path` (the one write_via_temporary and AtomicFileSet use):
// `path` + ".tmp-PID-XXXXXXXX". The name is registered for removal on a signal (below) until
// release_temporary_path(name), which the caller calls once the file is renamed or removed.
std::string temporary_path_for(const std::string& path);
void release_temporary_path(const std::string& temporary);

// Whether a file can be created next to `path`, found by creating and removing a temporary file
// there (so permissions, a read-only mount, a missing folder and a file in place of the folder
// all show, for any user). Errors (kIoError) say what is wrong with the folder, without `path`.
// For commands that check their outputs before a long computation; the write itself still
// reports its own failures.
Status check_folder_takes_files(const std::string& path);

// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove every registered temporary file
// (the writers above, and any temporary_path_for name not yet released) and then end the process
// by the same signal with its default action, so the exit status still says "killed by SIGINT".
// Final names are never touched: a file renamed into place is no longer a temporary, and the
// renames of one write (all files of an AtomicFileSet) run with the signals held off, so a signal
// leaves the earlier files or the whole new set, never a mix. A signal
// that is ignored or already has a handler when this is called is left alone. The zhc CLI calls
// it first thing; a program using the library may call it too. The handler is async-signal-safe
// (it reads fixed static slots: at most 128 live temporaries of under 4096 bytes are tracked;
// beyond that a temporary is removed on every normal path, only not on a signal).
void remove_temporaries_on_signals();

// Which files a command read and wrote, for build systems (`--depfile`, `zhc info --inputs`;
// docs/build-integration.md). While a FileRecorder is installed (ScopedFileRecording), every
// successful open for reading by read_file_bytes, read_file_prefix, FileRangeReader::open and the
// lightmap readers reports the path as given to it, and every published output (write_file_atomic,
// write_files_atomic, AtomicFileSet::commit, write_via_temporary, the streaming OpenEXR writer)
// reports the path it was renamed to. Thread-safe: readers on worker threads report too. Paths are
// kept in the order first seen, each once (by its spelling).
class FileRecorder {
public:
    void add_input(const std::string& path);
    void add_output(const std::string& path);
    std::vector<std::string> inputs() const;
    std::vector<std::string> outputs() const;

private:
    mutable std::mutex mutex_;
    std::vector<std::string> inputs_, outputs_;
};

// Installs `recorder` as the process's recorder for its lifetime (they do not nest: the previous
// one, usually none, is restored at the end).
class ScopedFileRecording {
public:
    explicit ScopedFileRecording(FileRecorder* recorder);
    ~ScopedFileRecording();
    ScopedFileRecording(const ScopedFileRecording&) = delete;
    ScopedFileRecording& operator=(const ScopedFileRecording&) = delete;

private:
    FileRecorder* previous_;
};

// Report a file read or published outside the functions above (no-op without a recorder).
void record_input(const std::string& path);
void record_output(const std::string& path);

// Lower-case extension including the dot ("" when none): "a/b.EXR" -> ".exr".
std::string file_extension(const std::string& path);

}  // namespace zhc
