// zhc/formats/exr_memory.h — reading OpenEXR from untrusted bytes in memory (shared by every
// EXR reader in formats/): an Imf::IStream over a byte span, and a header walk that runs before
// OpenEXR allocates anything sized by the header.
#pragma once

#include <ImfIO.h>

#include <cstdint>
#include <cstring>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>

#include "codec/status.h"

namespace zhc {

// An in-memory Imf::IStream; reading past the end throws, which OpenEXR turns into an error.
class ExrMemoryStream final : public Imf::IStream {
public:
    ExrMemoryStream(std::span<const std::uint8_t> bytes, const std::string& name)
        : Imf::IStream(name.c_str()), bytes_(bytes) {}
    bool read(char c[], int n) override {
        if (n < 0 || pos_ + static_cast<std::uint64_t>(n) > bytes_.size())
            throw std::runtime_error("unexpected end of file");
        std::memcpy(c, bytes_.data() + pos_, static_cast<size_t>(n));
        pos_ += static_cast<std::uint64_t>(n);
        return pos_ < bytes_.size();
    }
    std::uint64_t tellg() override { return pos_; }
    void seekg(std::uint64_t pos) override { pos_ = std::min<std::uint64_t>(pos, bytes_.size()); }

private:
    std::span<const std::uint8_t> bytes_;
    std::uint64_t pos_ = 0;
};

// Fails (kTruncated / kBadFormat / kUnsupported) unless every attribute of every header fits in the
// file; calls check_size(width, height) with the declared data window, whose error is returned.
Status validate_exr_header(std::span<const std::uint8_t> bytes, const std::string& name,
                           const std::function<Status(std::uint64_t, std::uint64_t)>& check_size);

}  // namespace zhc
