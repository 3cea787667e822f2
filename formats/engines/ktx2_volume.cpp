// zhc/formats/engines/ktx2_volume.cpp — uncompressed 2-D / 3-D KTX 2.0 writer and strict reader
// (see ktx2_volume.h). Field offsets and rules: the KTX 2.0 specification, sections 3 (file
// structure), 3.12 (DFD), 3.11 (key/value data); the DFD words: Khronos Data Format 1.3, section 5
// (basic descriptor block), as libktx's createDFDUnpacked (external/dfdutils/createdfd.c) fills them.
#include "formats/engines/ktx2_volume.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "formats/io/file_io.h"
#include "formats/io/le_bytes.h"

namespace zhc {
namespace {
using le::get32;
using le::get64;
using le::put32;
using le::put64;

constexpr std::uint8_t kIdentifier[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
constexpr std::size_t kDfdStart = 12 + 9 * 4 + 4 * 4 + 2 * 8 + 3 * 8;  // header, index, one level: 104
constexpr std::uint32_t kMaxKvdBytes = 65536;

// Khronos Data Format words.
constexpr std::uint32_t kModelRgbsda = 1, kPrimariesBt709 = 1, kTransferLinear = 1;
constexpr std::uint32_t kChannelAlpha = 15;
constexpr std::uint32_t kQualifierFloat = 0x80, kQualifierSigned = 0x40, kQualifierExponent = 0x20;

// One sample of the basic block: bitOffset, bitLength (stored minus one), channel with qualifiers,
// sampleLower, sampleUpper.
struct Sample {
    std::uint32_t offset, length_minus_1, channel, lower, upper;
    std::uint32_t word0() const { return offset | (length_minus_1 << 16) | (channel << 24); }
};

// The samples of a format, as libktx writes them: createDFDUnpacked for the RGBA formats (R, G, B,
// A in memory order, SFLOAT = float | signed with bounds -1.0f, 1.0f) and, for E5B9G9R9
// (vk2dfd.inl's own case), a 9-bit mantissa and the shared 5-bit exponent per colour channel.
std::vector<Sample> format_samples(std::uint32_t vk_format) {
    std::vector<Sample> s;
    if (vk_format == kVkFormatR16g16b16a16Sfloat || vk_format == kVkFormatR32g32b32a32Sfloat) {
        const std::uint32_t bits = vk_format == kVkFormatR16g16b16a16Sfloat ? 16 : 32;
        const std::uint32_t channels[4] = {0, 1, 2, kChannelAlpha};
        for (std::uint32_t c = 0; c < 4; ++c)
            s.push_back({c * bits, bits - 1, channels[c] | kQualifierFloat | kQualifierSigned, 0xBF800000u, 0x3F800000u});
    } else if (vk_format == kVkFormatE5b9g9r9UfloatPack32) {
        for (std::uint32_t c = 0; c < 3; ++c) {
            s.push_back({9 * c, 8, c, 0, 8448});                            // mantissa; upper 256 * (1 + 1/32)
            s.push_back({27, 4, c | kQualifierExponent, 15, 31});           // exponent, bias 15
        }
    }
    return s;
}

// The DFD zhc writes: dfdTotalSize, then one basic descriptor block.
std::vector<std::uint8_t> make_dfd(std::uint32_t vk_format) {
    const auto samples = format_samples(vk_format);
    const std::uint32_t block = 24 + 16 * static_cast<std::uint32_t>(samples.size());
    std::vector<std::uint8_t> d;
    put32(d, 4 + block);                       // dfdTotalSize
    put32(d, 0);                               // vendorId 0 (Khronos), descriptorType 0 (basic)
    put32(d, 2u | (block << 16));              // versionNumber 2 (KDF 1.3), descriptorBlockSize
    put32(d, kModelRgbsda | (kPrimariesBt709 << 8) | (kTransferLinear << 16));  // flags 0: straight alpha
    put32(d, 0);                               // texelBlockDimension 1x1x1x1 (stored minus one)
    put32(d, static_cast<std::uint32_t>(ktx2_texel_bytes(vk_format)));  // bytesPlane0
    put32(d, 0);                               // bytesPlane4..7
    for (const Sample& x : samples) {
        put32(d, x.word0());
        put32(d, 0);                           // samplePosition 0, 0, 0, 0
        put32(d, x.lower);
        put32(d, x.upper);
    }
    return d;
}

// typeSize (KTX2 section 3.2): the size of the format's data type, 4 for a packed 32-bit format.
std::uint32_t type_size(std::uint32_t vk_format) { return vk_format == kVkFormatR16g16b16a16Sfloat ? 2 : 4; }

std::size_t align_up(std::size_t v, std::size_t a) { return (v + a - 1) / a * a; }

Error bad(ErrorCode code, const std::string& name, const std::string& what) { return make_error(code, name + ": " + what); }

std::string at_byte(std::uint64_t at) { return " (byte " + std::to_string(at) + ")"; }

// The key/value data of entries sorted by key: u32 keyAndValueByteLength, the key, NUL, the value,
// padding to 4 bytes (the last entry's padding included, as kvdByteLength counts it).
Result<std::vector<std::uint8_t>> key_value_bytes(std::vector<Ktx2KeyValue> kv) {
    std::stable_sort(kv.begin(), kv.end(), [](const Ktx2KeyValue& a, const Ktx2KeyValue& b) { return a.key < b.key; });
    std::vector<std::uint8_t> out;
    for (std::size_t i = 0; i < kv.size(); ++i) {
        const auto& e = kv[i];
        if (e.key.empty() || e.key.find('\0') != std::string::npos)
            return make_error(ErrorCode::kInvalidArgument, "ktx2: a key/value key is empty or holds a NUL byte");
        if (i > 0 && kv[i - 1].key == e.key)
            return make_error(ErrorCode::kInvalidArgument, "ktx2: key '" + e.key + "' given twice");
        if (e.key.size() + 1 + e.value.size() > kMaxKvdBytes)
            return make_error(ErrorCode::kInvalidArgument, "ktx2: key/value data above " + std::to_string(kMaxKvdBytes) + " bytes");
        put32(out, static_cast<std::uint32_t>(e.key.size() + 1 + e.value.size()));
        out.insert(out.end(), e.key.begin(), e.key.end());
        out.push_back(0);
        out.insert(out.end(), e.value.begin(), e.value.end());
        out.resize(align_up(out.size(), 4), 0);
        if (out.size() > kMaxKvdBytes)
            return make_error(ErrorCode::kInvalidArgument, "ktx2: key/value data above " + std::to_string(kMaxKvdBytes) + " bytes");
    }
    return out;
}

// Checks the DFD at b[off, off + len) against the layout of `vk_format`; "" when it matches, else
// what differs (the caller adds the file name).
std::string check_dfd(std::span<const std::uint8_t> b, std::size_t off, std::uint32_t len, std::uint32_t vk_format) {
    const auto samples = format_samples(vk_format);
    const std::uint32_t block = 24 + 16 * static_cast<std::uint32_t>(samples.size());
    const std::string fmt = vk_format_label(vk_format);
    if (len < 4 || get32(b, off) != len)
        return "dfdTotalSize differs from dfdByteLength " + std::to_string(len) + at_byte(off);
    if (len < 4 + block)
        return "data format descriptor of " + std::to_string(len) + " bytes is too short for " + fmt + " (needs " +
               std::to_string(4 + block) + ")" + at_byte(off);
    const std::size_t p = off + 4;
    if (get32(b, p) != 0) return "the first descriptor block is not the Khronos basic block (vendorId/descriptorType)" + at_byte(p);
    const std::uint32_t version = get32(b, p + 4);
    if ((version & 0xFFFFu) != 2) return "descriptor versionNumber " + std::to_string(version & 0xFFFFu) + ", expected 2" + at_byte(p + 4);
    if ((version >> 16) != block)
        return "descriptorBlockSize " + std::to_string(version >> 16) + " but " + fmt + " has " +
               std::to_string(samples.size()) + " samples (" + std::to_string(block) + " bytes)" + at_byte(p + 6);
    const std::uint32_t model = get32(b, p + 8);
    if ((model & 0xFFu) != kModelRgbsda) return "colorModel " + std::to_string(model & 0xFFu) + ", expected 1 (RGBSDA)" + at_byte(p + 8);
    if (((model >> 16) & 0xFFu) != kTransferLinear)
        return "transferFunction " + std::to_string((model >> 16) & 0xFFu) + ", expected 1 (linear) for " + fmt + at_byte(p + 10);
    if (get32(b, p + 12) != 0) return "texelBlockDimension is not 1x1x1x1" + at_byte(p + 12);
    if (get32(b, p + 16) != ktx2_texel_bytes(vk_format) || get32(b, p + 20) != 0)
        return "bytesPlane0 " + std::to_string(get32(b, p + 16) & 0xFFu) + " (other planes must be 0), " + fmt + " has " +
               std::to_string(ktx2_texel_bytes(vk_format)) + " bytes a texel" + at_byte(p + 16);
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const std::size_t q = p + 24 + 16 * i;
        if (get32(b, q) != samples[i].word0() || get32(b, q + 4) != 0)
            return "sample " + std::to_string(i) + " (bit offset, length, channel or position) does not describe " + fmt + at_byte(q);
    }
    // Further descriptor blocks (vendor extensions) may follow the basic one: each must fit.
    std::size_t q = p + block;
    const std::size_t end = off + len;
    while (q < end) {
        if (end - q < 8) return "descriptor block header truncated" + at_byte(q);
        const std::uint32_t size = get32(b, q + 4) >> 16;
        if (size < 8 || size > end - q) return "descriptor block size " + std::to_string(size) + " does not fit the descriptor" + at_byte(q + 6);
        q += size;
    }
    return "";
}

}  // namespace

std::size_t ktx2_texel_bytes(std::uint32_t vk_format) {
    switch (vk_format) {
        case kVkFormatR16g16b16a16Sfloat: return 8;
        case kVkFormatR32g32b32a32Sfloat: return 16;
        case kVkFormatE5b9g9r9UfloatPack32: return 4;
        default: return 0;
    }
}

Result<std::vector<std::uint8_t>> encode_ktx2_texture(const Ktx2Texture& t) {
    const std::size_t tb = ktx2_texel_bytes(t.vk_format);
    if (tb == 0)
        return make_error(ErrorCode::kInvalidArgument, "ktx2: unsupported " + vk_format_label(t.vk_format) +
                                                           " (zhc writes vkFormat 97, 109 and 123 textures)");
    if (t.width == 0 || t.height == 0) return make_error(ErrorCode::kInvalidArgument, "ktx2: empty texture (width or height 0)");
    const std::uint64_t texels = std::uint64_t{t.width} * t.height;
    const std::uint64_t depth = std::max<std::uint32_t>(t.depth, 1);
    if (texels > (std::uint64_t{1} << 40) / depth / tb)
        return make_error(ErrorCode::kInvalidArgument, "ktx2: texture of " + std::to_string(t.width) + "x" + std::to_string(t.height) +
                                                           "x" + std::to_string(depth) + " texels is too large");
    const std::uint64_t level_bytes = texels * depth * tb;
    if (t.texels.size() != level_bytes)
        return make_error(ErrorCode::kInvalidArgument, "ktx2: " + std::to_string(t.texels.size()) + " bytes of texels, the size needs " +
                                                           std::to_string(level_bytes));
    auto kvd = key_value_bytes(t.key_values);
    if (!kvd) return kvd.error();
    const auto dfd = make_dfd(t.vk_format);
    const std::size_t kvd_offset = kvd->empty() ? 0 : kDfdStart + dfd.size();
    // byteOffset: a multiple of lcm(texel size, 4) = the texel size here.
    const std::size_t level_offset = align_up(kDfdStart + dfd.size() + kvd->size(), tb);
    std::vector<std::uint8_t> out(kIdentifier, kIdentifier + 12);
    out.reserve(level_offset + level_bytes);
    put32(out, t.vk_format);
    put32(out, type_size(t.vk_format));
    put32(out, t.width);
    put32(out, t.height);
    put32(out, t.depth);  // pixelDepth: 0 for 2-D
    put32(out, 0);        // layerCount
    put32(out, 1);        // faceCount
    put32(out, 1);        // levelCount
    put32(out, 0);        // supercompressionScheme: none
    put32(out, static_cast<std::uint32_t>(kDfdStart));
    put32(out, static_cast<std::uint32_t>(dfd.size()));
    put32(out, static_cast<std::uint32_t>(kvd_offset));
    put32(out, static_cast<std::uint32_t>(kvd->size()));
    put64(out, 0);  // sgdByteOffset
    put64(out, 0);  // sgdByteLength
    put64(out, level_offset);
    put64(out, level_bytes);
    put64(out, level_bytes);  // uncompressedByteLength
    out.insert(out.end(), dfd.begin(), dfd.end());
    out.insert(out.end(), kvd->begin(), kvd->end());
    out.resize(level_offset, 0);
    out.insert(out.end(), t.texels.begin(), t.texels.end());
    return out;
}

Result<Ktx2Texture> decode_ktx2_texture(std::span<const std::uint8_t> b, const std::string& name, std::uint64_t max_texels) {
    if (b.size() < 12 || std::memcmp(b.data(), kIdentifier, 12) != 0)
        return bad(ErrorCode::kBadFormat, name, "not a KTX2 file (bad identifier at byte 0)" + git_lfs_hint(b));
    if (b.size() < kDfdStart) return bad(ErrorCode::kTruncated, name, "header truncated (file ends before byte 104)");
    Ktx2Texture t;
    t.vk_format = get32(b, 12);
    const std::uint32_t tsize = get32(b, 16), w = get32(b, 20), h = get32(b, 24), d = get32(b, 28), layers = get32(b, 32),
                        faces = get32(b, 36), levels = get32(b, 40), scheme = get32(b, 44);
    // Everything this reader does not do, named in one message.
    std::vector<std::string> unsupported;
    const std::size_t tb = ktx2_texel_bytes(t.vk_format);
    if (tb == 0)
        unsupported.push_back("format " + vk_format_label(t.vk_format) + " (byte 12; zhc reads vkFormat 97 R16G16B16A16_SFLOAT, "
                                                                         "109 R32G32B32A32_SFLOAT, 123 E5B9G9R9_UFLOAT_PACK32)");
    if (levels != 1)
        unsupported.push_back(levels == 0 ? std::string("levelCount 0 (mip levels for the loader to make; byte 40)")
                                          : std::to_string(levels) + " mip levels (byte 40; zhc reads one)");
    if (scheme != 0) {
        const char* schemes[] = {"none", "BasisLZ", "Zstandard", "ZLIB"};
        unsupported.push_back(std::string(scheme < 4 ? schemes[scheme] : "an unknown") + " supercompression (scheme " +
                              std::to_string(scheme) + ", byte 44)");
    }
    if (layers != 0) unsupported.push_back("an array of " + std::to_string(layers) + " layers (byte 32)");
    if (faces == 6) unsupported.push_back("a cube map (faceCount 6, byte 36)");
    if (w != 0 && h == 0) unsupported.push_back("a 1-D texture (pixelHeight 0, byte 24)");
    if (!unsupported.empty()) {
        std::string all;
        for (std::size_t i = 0; i < unsupported.size(); ++i) all += (i ? ", " : "") + unsupported[i];
        return bad(ErrorCode::kUnsupported, name, "unsupported KTX2 texture: " + all);
    }
    if (faces != 1) return bad(ErrorCode::kBadFormat, name, "faceCount " + std::to_string(faces) + ", must be 1 or 6 (byte 36)");
    if (tsize != type_size(t.vk_format))
        return bad(ErrorCode::kBadFormat, name, "typeSize " + std::to_string(tsize) + ", " + vk_format_label(t.vk_format) + " needs " +
                                                    std::to_string(type_size(t.vk_format)) + " (byte 16)");
    if (w == 0) return bad(ErrorCode::kBadFormat, name, "pixelWidth 0 (byte 20)");
    const std::uint64_t depth = std::max<std::uint32_t>(d, 1);
    const std::uint64_t plane = std::uint64_t{w} * h;  // < 2^64
    max_texels = std::min<std::uint64_t>(max_texels, std::uint64_t{1} << 40);  // level bytes stay far below 2^64
    if (plane > max_texels || depth > max_texels / plane)
        return bad(ErrorCode::kTooLarge, name, std::to_string(w) + "x" + std::to_string(h) + "x" + std::to_string(depth) +
                                                   " texels exceed the limit of " + std::to_string(max_texels) + " (bytes 20-31)");
    const std::uint64_t level_bytes = plane * depth * tb;

    const std::uint32_t dfd_off = get32(b, 48), dfd_len = get32(b, 52), kvd_off = get32(b, 56), kvd_len = get32(b, 60);
    const std::uint64_t sgd_off = get64(b, 64), sgd_len = get64(b, 72);
    const std::uint64_t lvl_off = get64(b, 80), lvl_len = get64(b, 88), lvl_ulen = get64(b, 96);
    if (sgd_off != 0 || sgd_len != 0)
        return bad(ErrorCode::kBadFormat, name, "supercompression global data without a scheme (bytes 64-79)");
    if (dfd_off != kDfdStart)
        return bad(ErrorCode::kBadFormat, name, "dfdByteOffset " + std::to_string(dfd_off) + ", the DFD follows the level index at 104 (byte 48)");
    if (dfd_len > b.size() - kDfdStart)
        return bad(ErrorCode::kTruncated, name, "file ends inside the data format descriptor (" + std::to_string(dfd_len) + " bytes at byte 104)");
    if (const std::string why = check_dfd(b, kDfdStart, dfd_len, t.vk_format); !why.empty())
        return bad(ErrorCode::kBadFormat, name, why);
    const std::uint64_t dfd_end = kDfdStart + std::uint64_t{dfd_len};
    std::uint64_t meta_end = dfd_end;
    if (kvd_len != 0) {
        if (kvd_len > kMaxKvdBytes)
            return bad(ErrorCode::kTooLarge, name, "key/value data of " + std::to_string(kvd_len) + " bytes exceeds the limit " +
                                                       std::to_string(kMaxKvdBytes) + " (byte 60)");
        if (kvd_off < dfd_end || kvd_off % 4 != 0)
            return bad(ErrorCode::kBadFormat, name, "kvdByteOffset " + std::to_string(kvd_off) + " overlaps the DFD or is not a multiple of 4 (byte 56)");
        if (std::uint64_t{kvd_off} + kvd_len > b.size())
            return bad(ErrorCode::kTruncated, name, "file ends inside the key/value data (byte " + std::to_string(kvd_off) + ")");
        std::size_t at = kvd_off;
        const std::size_t end = std::size_t{kvd_off} + kvd_len;
        while (at < end) {
            if (end - at < 4) return bad(ErrorCode::kBadFormat, name, "key/value entry truncated" + at_byte(at));
            const std::uint32_t len = get32(b, at);
            if (len > end - at - 4) return bad(ErrorCode::kBadFormat, name, "key/value entry longer than the key/value data" + at_byte(at));
            const std::uint8_t* p = b.data() + at + 4;
            const auto* nul = static_cast<const std::uint8_t*>(std::memchr(p, 0, len));
            if (nul == nullptr || nul == p)
                return bad(ErrorCode::kBadFormat, name, "key/value entry without a NUL-terminated key" + at_byte(at));
            Ktx2KeyValue e;
            e.key.assign(reinterpret_cast<const char*>(p), static_cast<std::size_t>(nul - p));
            for (const auto& prior : t.key_values)
                if (prior.key == e.key) return bad(ErrorCode::kBadFormat, name, "key '" + e.key + "' appears twice" + at_byte(at));
            e.value.assign(nul + 1, p + len);
            t.key_values.push_back(std::move(e));
            const std::size_t next = align_up(at + 4 + len, 4);
            if (next > end) return bad(ErrorCode::kBadFormat, name, "key/value entry's padding runs past the key/value data" + at_byte(at));
            at = next;
        }
        meta_end = std::uint64_t{kvd_off} + kvd_len;
    } else if (kvd_off != 0) {
        return bad(ErrorCode::kBadFormat, name, "kvdByteOffset " + std::to_string(kvd_off) + " without kvdByteLength (byte 56)");
    }
    const std::string dims = std::to_string(w) + "x" + std::to_string(h) + (d ? "x" + std::to_string(d) : "");
    if (lvl_len != level_bytes || lvl_ulen != level_bytes)
        return bad(ErrorCode::kBadFormat, name, "level 0 byteLength " + std::to_string(lvl_len) + " / uncompressedByteLength " +
                                                    std::to_string(lvl_ulen) + " but " + dims + " texels of " + std::to_string(tb) +
                                                    " bytes need " + std::to_string(level_bytes) + " (bytes 88-103)");
    if (lvl_off % tb != 0 || lvl_off < meta_end)
        return bad(ErrorCode::kBadFormat, name, "level 0 byteOffset " + std::to_string(lvl_off) + " is not a multiple of " +
                                                    std::to_string(tb) + " or overlaps the DFD / key/value data (byte 80)");
    if (lvl_off > b.size() || b.size() - lvl_off < lvl_len)
        return bad(ErrorCode::kTruncated, name, "file ends inside the level data (needs " + std::to_string(lvl_off + lvl_len) +
                                                    " bytes, has " + std::to_string(b.size()) + ")");
    if (b.size() != lvl_off + lvl_len)
        return bad(ErrorCode::kTrailingBytes, name, std::to_string(b.size() - lvl_off - lvl_len) + " bytes after the level data" +
                                                        at_byte(lvl_off + lvl_len));
    t.width = w;
    t.height = h;
    t.depth = d;
    t.texels.assign(b.begin() + static_cast<std::ptrdiff_t>(lvl_off), b.end());
    return t;
}

}  // namespace zhc
