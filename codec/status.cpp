#include "status.h"

namespace zhc {

const char* error_code_name(ErrorCode code) {
    switch (code) {
        case ErrorCode::kInvalidArgument: return "invalid-argument";
        case ErrorCode::kIoError: return "io-error";
        case ErrorCode::kBadFormat: return "bad-format";
        case ErrorCode::kTruncated: return "truncated";
        case ErrorCode::kTrailingBytes: return "trailing-bytes";
        case ErrorCode::kChecksum: return "checksum";
        case ErrorCode::kUnsupported: return "unsupported";
        case ErrorCode::kTooLarge: return "too-large";
        case ErrorCode::kInvalidValue: return "invalid-value";
        case ErrorCode::kInternal: return "internal";
    }
    return "internal";
}

}  // namespace zhc
