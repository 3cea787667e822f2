// zhc/tests/vk/vk_compute.h — headless Vulkan compute for the runtime-shader test and benchmark:
// one instance, one CPU/GPU physical device, one compute queue, storage buffers in host-visible
// coherent memory, one pipeline per SPIR-V module. Used by tests/test_runtime_vk.cpp and
// bench/bench_runtime.cpp (the two must run the same set-up).
//
// Not thread-safe; errors are reported as strings (the callers are a test and a benchmark).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace zhc::vk {

// Points the Vulkan loader at one ICD manifest only (VK_DRIVER_FILES and the older
// VK_ICD_FILENAMES), e.g. Mesa lavapipe's lvp_icd.x86_64.json. Call before Context::create.
void force_icd(const std::string& icd_json_path);

// Reads a SPIR-V binary; empty on failure.
std::vector<std::uint32_t> read_spirv(const std::string& path);

class Context;

// A sampled 3D image for Context::make_kernel: `format` a VkFormat, texels tightly packed
// (x fastest, then y, then z), uploaded once; sampled with a linear, clamp-to-edge sampler.
struct Image3D {
    std::uint32_t format = 0;
    std::uint32_t width = 1, height = 1, depth = 1;
    std::span<const std::uint8_t> texels;
};

// A compute pipeline bound to `buffers.size()` storage buffers (bindings 0.. of set 0). Buffer
// contents are host-visible: write with data(), dispatch, read with data().
class Kernel {
public:
    ~Kernel();
    Kernel(const Kernel&) = delete;
    Kernel& operator=(const Kernel&) = delete;
    std::uint8_t* data(std::size_t binding);
    std::size_t size(std::size_t binding) const;
    // Records one dispatch of `groups_x` work groups, submits it and waits for the queue (vkQueueWaitIdle).
    // Returns the wall-clock seconds of submit + wait, or a negative value on failure (*error set).
    double dispatch(std::uint32_t groups_x, std::string* error);

private:
    friend class Context;
    struct Impl;
    explicit Kernel(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

class Context {
public:
    // Creates an instance and a device on the first physical device of type CPU (lavapipe), or, when
    // `require_cpu` is false, on the first device with a compute queue. nullptr + *error on failure.
    static std::unique_ptr<Context> create(bool require_cpu, std::string* error);
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    const std::string& device_name() const;
    // Creates the pipeline of `spirv` (entry point "main") and one storage buffer per entry of
    // `buffer_sizes` (bytes, each > 0, zero-initialised). nullptr + *error on failure.
    std::unique_ptr<Kernel> make_kernel(std::span<const std::uint32_t> spirv, std::span<const std::size_t> buffer_sizes,
                                        std::string* error);
    // The same, plus (when `images` is not empty) one sampler (VK_FILTER_LINEAR, clamp to edge,
    // unnormalised coordinates off) at binding buffer_sizes.size() and the images as sampled images
    // at the bindings after it.
    std::unique_ptr<Kernel> make_kernel(std::span<const std::uint32_t> spirv, std::span<const std::size_t> buffer_sizes,
                                        std::span<const Image3D> images, std::string* error);

private:
    struct Impl;
    explicit Context(std::unique_ptr<Impl> impl);
    static bool upload_images(Impl& ctx, Kernel::Impl& k, std::span<const Image3D> in, std::uint32_t first, std::string* error);
    std::unique_ptr<Impl> impl_;
};

// runtime/zhc.hlsl's encoding id of a codec table entry: its "#define ZHC_<NAME> <id>u" line in
// the file's encodings section (NAME = the entry's name in upper case), read from the source tree
// at the first call. -1 when the file has no such line (the entry has no HLSL decoder).
int hlsl_encoding(std::string_view name);
// The section's ZHC_ENCODING_COUNT; -1 when the file cannot be read.
int hlsl_encoding_count();

}  // namespace zhc::vk
