// zhc/codec/status.h — error values returned across zhc's library APIs (never exceptions).
//
// Every failure carries a stable code and a one-line message naming the file (when there is
// one), what is wrong and where (field, byte offset). The CLI maps codes to exit codes
// (README "Exit codes").
//
// Thread safety (docs/api.md): every function here is reentrant and keeps no state between
// calls; calls may run concurrently on different arguments and on the same const ones.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace zhc {

// One numbering with the C runtime's `enum zhc_error` (runtime/zhc_runtime.h): the classes both
// report have the same value (ZHC_ERR_ARGUMENT = 1 ... ZHC_ERR_TRAILING_BYTES = 8; 9 and 10 are the
// runtime's ZHC_ERR_COMPRESSED and ZHC_ERR_NOT_GRID), the library-only ones start at 16. The CLI maps them to exit codes
// (cli/main.cpp exit_code_for); the table of all three is in docs/inputs.md "Error classes".
enum class ErrorCode {
    kInvalidArgument = 1,  // the caller's mistake: bad option, unknown representation name
    kTruncated = 2,        // ends before the data it declares
    kBadFormat = 3,        // not the format it claims to be: bad magic, malformed header or field
    kUnsupported = 4,      // well-formed but uses a feature/version zhc does not support
    kChecksum = 5,         // stored checksum does not match
    kTooLarge = 6,         // declared sizes exceed zhc's limits (checked before allocating)
    kInvalidValue = 7,     // NaN/Inf or otherwise unusable numbers in the data
    kTrailingBytes = 8,    // data after the declared end
    kIoError = 16,         // file missing, unreadable, not writable
    kInternal = 17,        // a bug in zhc
};

struct Error {
    ErrorCode code = ErrorCode::kInternal;
    std::string message;  // one line: "<file>: <what is wrong> (<where>)"
};

// A value or an Error. Small on purpose: std::expected is C++23 and clang 14 (the fuzzers'
// compiler) cannot use libstdc++'s.
template <class T>
class Result {
public:
    Result(T value) : v_(std::move(value)) {}
    Result(Error error) : v_(std::move(error)) {}
    bool ok() const { return v_.index() == 0; }
    explicit operator bool() const { return ok(); }
    T& value() & { return std::get<0>(v_); }
    const T& value() const& { return std::get<0>(v_); }
    T&& value() && { return std::get<0>(std::move(v_)); }
    T* operator->() { return &std::get<0>(v_); }
    const T* operator->() const { return &std::get<0>(v_); }
    T& operator*() & { return std::get<0>(v_); }
    const T& operator*() const& { return std::get<0>(v_); }
    const Error& error() const { return std::get<1>(v_); }

private:
    std::variant<T, Error> v_;
};

struct Ok {};
using Status = Result<Ok>;

inline Error make_error(ErrorCode code, std::string message) { return Error{code, std::move(message)}; }

}  // namespace zhc
