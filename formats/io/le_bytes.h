// Little-endian byte access shared by the container readers and writers (KTX2, DDS, GLB, cube
// maps, .zhp, OpenEXR headers). Readers check bounds before calling these; the helpers themselves do not.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace zhc::le {

inline std::uint16_t load16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
inline std::uint32_t load32(const std::uint8_t* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}
inline float load_f32(const std::uint8_t* p) {
    const std::uint32_t v = load32(p);
    float f;
    std::memcpy(&f, &v, 4);
    return f;
}
inline std::uint64_t load64(const std::uint8_t* p) { return load32(p) | std::uint64_t(load32(p + 4)) << 32; }
inline double load_f64(const std::uint8_t* p) {
    const std::uint64_t v = load64(p);
    double d;
    std::memcpy(&d, &v, 8);
    return d;
}
// The low `bytes` bytes of v at p (in place; 1 <= bytes <= 8), and their float counterparts.
inline void store(std::uint8_t* p, std::uint64_t v, int bytes) {
    for (int b = 0; b < bytes; ++b) p[b] = static_cast<std::uint8_t>(v >> (8 * b));
}
inline std::uint64_t load(const std::uint8_t* p, int bytes) {
    std::uint64_t v = 0;
    for (int b = 0; b < bytes; ++b) v |= std::uint64_t(p[b]) << (8 * b);
    return v;
}
inline void store_f32(std::uint8_t* p, float f) {
    std::uint32_t v;
    std::memcpy(&v, &f, 4);
    store(p, v, 4);
}
inline void store_f64(std::uint8_t* p, double d) {
    std::uint64_t v;
    std::memcpy(&v, &d, 8);
    store(p, v, 8);
}
inline std::uint32_t get32(std::span<const std::uint8_t> b, std::size_t off) { return load32(b.data() + off); }
inline std::uint64_t get64(std::span<const std::uint8_t> b, std::size_t off) {
    return load64(b.data() + off);
}
// Appends v to b.
inline void put32(std::vector<std::uint8_t>& b, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}
inline void put64(std::vector<std::uint8_t>& b, std::uint64_t v) {
    for (int k = 0; k < 8; ++k) b.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

}  // namespace zhc::le
