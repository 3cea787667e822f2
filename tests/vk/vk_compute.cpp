// zhc/tests/vk/vk_compute.cpp — see vk_compute.h.
#include "vk_compute.h"

#include <vulkan/vulkan.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

namespace zhc::vk {
namespace {

std::string vk_error(const char* what, VkResult r) { return std::string(what) + " failed (VkResult " + std::to_string(r) + ")"; }

}  // namespace

void force_icd(const std::string& icd_json_path) {
    ::setenv("VK_DRIVER_FILES", icd_json_path.c_str(), 1);
    ::setenv("VK_ICD_FILENAMES", icd_json_path.c_str(), 1);
}

std::vector<std::uint32_t> read_spirv(const std::string& path) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) return {};
    const std::streamoff size = in.tellg();
    if (size <= 0 || size % 4 != 0) return {};
    std::vector<std::uint32_t> words(static_cast<std::size_t>(size) / 4);
    in.seekg(0);
    in.read(reinterpret_cast<char*>(words.data()), size);
    if (!in) return {};
    return words;
}

struct Context::Impl {
    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    std::uint32_t queue_family = 0;
    VkPhysicalDeviceMemoryProperties memory{};
    std::string name;
    ~Impl() {
        if (device) vkDestroyDevice(device, nullptr);
        if (instance) vkDestroyInstance(instance, nullptr);
    }
};

struct Kernel::Impl {
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    std::vector<VkBuffer> buffers;
    std::vector<VkDeviceMemory> memories;
    std::vector<std::uint8_t*> mapped;
    std::vector<std::size_t> sizes;
    VkShaderModule module = VK_NULL_HANDLE;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VkCommandPool command_pool = VK_NULL_HANDLE;
    VkCommandBuffer command_buffer = VK_NULL_HANDLE;
    std::vector<VkImage> images;
    std::vector<VkImageView> views;
    std::vector<VkDeviceMemory> image_memories;
    VkSampler sampler = VK_NULL_HANDLE;
    ~Impl() {
        if (!device) return;
        vkDeviceWaitIdle(device);
        for (VkImageView v : views) vkDestroyImageView(device, v, nullptr);
        for (VkImage i : images) vkDestroyImage(device, i, nullptr);
        for (VkDeviceMemory m : image_memories) vkFreeMemory(device, m, nullptr);
        if (sampler) vkDestroySampler(device, sampler, nullptr);
        if (command_pool) vkDestroyCommandPool(device, command_pool, nullptr);
        if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
        if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
        if (pipeline_layout) vkDestroyPipelineLayout(device, pipeline_layout, nullptr);
        if (set_layout) vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
        if (module) vkDestroyShaderModule(device, module, nullptr);
        for (std::size_t i = 0; i < buffers.size(); ++i) {
            if (i < mapped.size() && mapped[i]) vkUnmapMemory(device, memories[i]);
            vkDestroyBuffer(device, buffers[i], nullptr);
        }
        for (VkDeviceMemory m : memories) vkFreeMemory(device, m, nullptr);
    }
};

Context::Context(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::~Context() = default;
const std::string& Context::device_name() const { return impl_->name; }

Kernel::Kernel(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Kernel::~Kernel() = default;
std::uint8_t* Kernel::data(std::size_t binding) { return impl_->mapped.at(binding); }
std::size_t Kernel::size(std::size_t binding) const { return impl_->sizes.at(binding); }

std::unique_ptr<Context> Context::create(bool require_cpu, std::string* error) {
    auto impl = std::make_unique<Impl>();
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "zhc";
    app.apiVersion = VK_API_VERSION_1_1;
    VkInstanceCreateInfo ici{};
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pApplicationInfo = &app;
    if (VkResult r = vkCreateInstance(&ici, nullptr, &impl->instance); r != VK_SUCCESS) {
        impl->instance = VK_NULL_HANDLE;
        *error = vk_error("vkCreateInstance", r);
        return nullptr;
    }
    std::uint32_t count = 0;
    vkEnumeratePhysicalDevices(impl->instance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    if (count) vkEnumeratePhysicalDevices(impl->instance, &count, devices.data());
    for (VkPhysicalDevice pd : devices) {
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(pd, &props);
        if (require_cpu && props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) continue;
        std::uint32_t qcount = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(pd, &qcount, nullptr);
        std::vector<VkQueueFamilyProperties> families(qcount);
        vkGetPhysicalDeviceQueueFamilyProperties(pd, &qcount, families.data());
        for (std::uint32_t q = 0; q < qcount; ++q)
            if (families[q].queueFlags & VK_QUEUE_COMPUTE_BIT) {
                impl->physical = pd;
                impl->queue_family = q;
                impl->name = props.deviceName;
                break;
            }
        if (impl->physical) break;
    }
    if (!impl->physical) {
        *error = std::to_string(count) + " Vulkan device(s), none " + (require_cpu ? "of type CPU " : "") +
                 "with a compute queue";
        return nullptr;
    }
    vkGetPhysicalDeviceMemoryProperties(impl->physical, &impl->memory);
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{};
    qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qci.queueFamilyIndex = impl->queue_family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{};
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    if (VkResult r = vkCreateDevice(impl->physical, &dci, nullptr, &impl->device); r != VK_SUCCESS) {
        impl->device = VK_NULL_HANDLE;
        *error = vk_error("vkCreateDevice", r);
        return nullptr;
    }
    vkGetDeviceQueue(impl->device, impl->queue_family, 0, &impl->queue);
    return std::unique_ptr<Context>(new Context(std::move(impl)));
}

std::unique_ptr<Kernel> Context::make_kernel(std::span<const std::uint32_t> spirv, std::span<const std::size_t> buffer_sizes,
                                             std::string* error) {
    return make_kernel(spirv, buffer_sizes, {}, error);
}

namespace {

std::uint32_t memory_type(const VkPhysicalDeviceMemoryProperties& mem, std::uint32_t bits, VkMemoryPropertyFlags want) {
    for (std::uint32_t t = 0; t < mem.memoryTypeCount; ++t)
        if ((bits & (1u << t)) && (mem.memoryTypes[t].propertyFlags & want) == want) return t;
    return UINT32_MAX;
}

}  // namespace

// Creates the sampler and the images of `in` (optimal tiling, device memory), uploads them through a
// staging buffer, transitions them to SHADER_READ_ONLY_OPTIMAL and writes their descriptors
// (sampler at binding `first`, images after it).
bool Context::upload_images(Context::Impl& ctx, Kernel::Impl& k, std::span<const Image3D> in, std::uint32_t first,
                            std::string* error) {
    const VkDevice dev = k.device;
    VkSamplerCreateInfo sci{};
    sci.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    sci.magFilter = VK_FILTER_LINEAR;
    sci.minFilter = VK_FILTER_LINEAR;
    sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    sci.maxLod = 0.0f;
    if (VkResult r = vkCreateSampler(dev, &sci, nullptr, &k.sampler); r != VK_SUCCESS) {
        *error = vk_error("vkCreateSampler", r);
        return false;
    }
    std::size_t staging_size = 0;
    for (const Image3D& im : in) staging_size += (im.texels.size() + 15) / 16 * 16;
    VkBufferCreateInfo bci{};
    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = std::max<std::size_t>(16, staging_size);
    bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    VkBuffer staging = VK_NULL_HANDLE;
    VkDeviceMemory staging_memory = VK_NULL_HANDLE;
    struct Cleanup {
        VkDevice dev;
        VkBuffer* b;
        VkDeviceMemory* m;
        ~Cleanup() {
            if (*b) vkDestroyBuffer(dev, *b, nullptr);
            if (*m) vkFreeMemory(dev, *m, nullptr);
        }
    } cleanup{dev, &staging, &staging_memory};
    if (VkResult r = vkCreateBuffer(dev, &bci, nullptr, &staging); r != VK_SUCCESS) {
        *error = vk_error("vkCreateBuffer (staging)", r);
        return false;
    }
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(dev, staging, &req);
    VkMemoryAllocateInfo mai{};
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memory_type(ctx.memory, req.memoryTypeBits,
                                      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    if (mai.memoryTypeIndex == UINT32_MAX) {
        *error = "no host-visible coherent memory type";
        return false;
    }
    if (VkResult r = vkAllocateMemory(dev, &mai, nullptr, &staging_memory); r != VK_SUCCESS) {
        *error = vk_error("vkAllocateMemory (staging)", r);
        return false;
    }
    vkBindBufferMemory(dev, staging, staging_memory, 0);
    void* mapped = nullptr;
    if (VkResult r = vkMapMemory(dev, staging_memory, 0, VK_WHOLE_SIZE, 0, &mapped); r != VK_SUCCESS) {
        *error = vk_error("vkMapMemory (staging)", r);
        return false;
    }
    std::vector<VkDeviceSize> offsets;
    {
        std::size_t at = 0;
        for (const Image3D& im : in) {
            offsets.push_back(at);
            if (!im.texels.empty()) std::memcpy(static_cast<std::uint8_t*>(mapped) + at, im.texels.data(), im.texels.size());
            at += (im.texels.size() + 15) / 16 * 16;
        }
    }
    vkUnmapMemory(dev, staging_memory);
    for (const Image3D& im : in) {
        VkImageCreateInfo ici{};
        ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
        ici.imageType = VK_IMAGE_TYPE_3D;
        ici.format = static_cast<VkFormat>(im.format);
        ici.extent = {im.width, im.height, im.depth};
        ici.mipLevels = 1;
        ici.arrayLayers = 1;
        ici.samples = VK_SAMPLE_COUNT_1_BIT;
        ici.tiling = VK_IMAGE_TILING_OPTIMAL;
        ici.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
        ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        VkImage image;
        if (VkResult r = vkCreateImage(dev, &ici, nullptr, &image); r != VK_SUCCESS) {
            *error = vk_error("vkCreateImage", r);
            return false;
        }
        k.images.push_back(image);
        VkMemoryRequirements ireq;
        vkGetImageMemoryRequirements(dev, image, &ireq);
        VkMemoryAllocateInfo imai{};
        imai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        imai.allocationSize = ireq.size;
        imai.memoryTypeIndex = memory_type(ctx.memory, ireq.memoryTypeBits, 0);
        VkDeviceMemory memory;
        if (VkResult r = vkAllocateMemory(dev, &imai, nullptr, &memory); r != VK_SUCCESS) {
            *error = vk_error("vkAllocateMemory (image)", r);
            return false;
        }
        k.image_memories.push_back(memory);
        vkBindImageMemory(dev, image, memory, 0);
        VkImageViewCreateInfo vci{};
        vci.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
        vci.image = image;
        vci.viewType = VK_IMAGE_VIEW_TYPE_3D;
        vci.format = ici.format;
        vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        VkImageView view;
        if (VkResult r = vkCreateImageView(dev, &vci, nullptr, &view); r != VK_SUCCESS) {
            *error = vk_error("vkCreateImageView", r);
            return false;
        }
        k.views.push_back(view);
    }
    // Upload: UNDEFINED -> TRANSFER_DST, copy, -> SHADER_READ_ONLY.
    VkCommandBuffer cb = k.command_buffer;
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkBeginCommandBuffer(cb, &begin);
    for (std::size_t i = 0; i < in.size(); ++i) {
        VkImageMemoryBarrier b{};
        b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
        b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        b.image = k.images[i];
        b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &b);
        VkBufferImageCopy copy{};
        copy.bufferOffset = offsets[i];
        copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        copy.imageExtent = {in[i].width, in[i].height, in[i].depth};
        vkCmdCopyBufferToImage(cb, staging, k.images[i], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
        b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
        b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr, 0, nullptr, 1, &b);
    }
    vkEndCommandBuffer(cb);
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    if (VkResult r = vkQueueSubmit(k.queue, 1, &submit, VK_NULL_HANDLE); r != VK_SUCCESS) {
        *error = vk_error("vkQueueSubmit (upload)", r);
        return false;
    }
    vkQueueWaitIdle(k.queue);
    // Descriptors.
    VkDescriptorImageInfo sampler_info{k.sampler, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED};
    std::vector<VkDescriptorImageInfo> image_infos(in.size());
    std::vector<VkWriteDescriptorSet> writes(in.size() + 1);
    writes[0] = {};
    writes[0].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[0].dstSet = k.set;
    writes[0].dstBinding = first;
    writes[0].descriptorCount = 1;
    writes[0].descriptorType = VK_DESCRIPTOR_TYPE_SAMPLER;
    writes[0].pImageInfo = &sampler_info;
    for (std::size_t i = 0; i < in.size(); ++i) {
        image_infos[i] = {VK_NULL_HANDLE, k.views[i], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
        writes[i + 1] = {};
        writes[i + 1].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i + 1].dstSet = k.set;
        writes[i + 1].dstBinding = first + 1 + static_cast<std::uint32_t>(i);
        writes[i + 1].descriptorCount = 1;
        writes[i + 1].descriptorType = VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
        writes[i + 1].pImageInfo = &image_infos[i];
    }
    vkUpdateDescriptorSets(dev, static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
    return true;
}

std::unique_ptr<Kernel> Context::make_kernel(std::span<const std::uint32_t> spirv, std::span<const std::size_t> buffer_sizes,
                                             std::span<const Image3D> images_in, std::string* error) {
    const VkDevice dev = impl_->device;
    auto k = std::make_unique<Kernel::Impl>();
    k->device = dev;
    k->queue = impl_->queue;
    const auto n = static_cast<std::uint32_t>(buffer_sizes.size());
    for (std::size_t size : buffer_sizes) {
        VkBufferCreateInfo bci{};
        bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
        bci.size = size;
        bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
        VkBuffer buffer;
        if (VkResult r = vkCreateBuffer(dev, &bci, nullptr, &buffer); r != VK_SUCCESS) {
            *error = vk_error("vkCreateBuffer", r);
            return nullptr;
        }
        k->buffers.push_back(buffer);
        VkMemoryRequirements req;
        vkGetBufferMemoryRequirements(dev, buffer, &req);
        const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        std::uint32_t type = UINT32_MAX;
        for (std::uint32_t t = 0; t < impl_->memory.memoryTypeCount; ++t)
            if ((req.memoryTypeBits & (1u << t)) && (impl_->memory.memoryTypes[t].propertyFlags & want) == want) {
                type = t;
                break;
            }
        if (type == UINT32_MAX) {
            *error = "no host-visible coherent memory type";
            return nullptr;
        }
        VkMemoryAllocateInfo mai{};
        mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        mai.allocationSize = req.size;
        mai.memoryTypeIndex = type;
        VkDeviceMemory memory;
        if (VkResult r = vkAllocateMemory(dev, &mai, nullptr, &memory); r != VK_SUCCESS) {
            *error = vk_error("vkAllocateMemory", r);
            return nullptr;
        }
        k->memories.push_back(memory);
        vkBindBufferMemory(dev, buffer, memory, 0);
        void* p = nullptr;
        if (VkResult r = vkMapMemory(dev, memory, 0, size, 0, &p); r != VK_SUCCESS) {
            *error = vk_error("vkMapMemory", r);
            return nullptr;
        }
        std::memset(p, 0, size);
        k->mapped.push_back(static_cast<std::uint8_t*>(p));
        k->sizes.push_back(size);
    }
    VkShaderModuleCreateInfo smci{};
    smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    smci.codeSize = spirv.size() * 4;
    smci.pCode = spirv.data();
    if (VkResult r = vkCreateShaderModule(dev, &smci, nullptr, &k->module); r != VK_SUCCESS) {
        *error = vk_error("vkCreateShaderModule", r);
        return nullptr;
    }
    std::vector<VkDescriptorSetLayoutBinding> bindings(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        bindings[i] = {};
        bindings[i].binding = i;
        bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    const auto n_img = static_cast<std::uint32_t>(images_in.size());
    if (n_img > 0) {
        for (std::uint32_t i = 0; i <= n_img; ++i) {
            VkDescriptorSetLayoutBinding b{};
            b.binding = n + i;
            b.descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_SAMPLER : VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
            b.descriptorCount = 1;
            b.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
            bindings.push_back(b);
        }
    }
    VkDescriptorSetLayoutCreateInfo dslci{};
    dslci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    dslci.bindingCount = static_cast<std::uint32_t>(bindings.size());
    dslci.pBindings = bindings.data();
    if (VkResult r = vkCreateDescriptorSetLayout(dev, &dslci, nullptr, &k->set_layout); r != VK_SUCCESS) {
        *error = vk_error("vkCreateDescriptorSetLayout", r);
        return nullptr;
    }
    VkPipelineLayoutCreateInfo plci{};
    plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &k->set_layout;
    if (VkResult r = vkCreatePipelineLayout(dev, &plci, nullptr, &k->pipeline_layout); r != VK_SUCCESS) {
        *error = vk_error("vkCreatePipelineLayout", r);
        return nullptr;
    }
    VkComputePipelineCreateInfo cpci{};
    cpci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    cpci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpci.stage.module = k->module;
    cpci.stage.pName = "main";
    cpci.layout = k->pipeline_layout;
    if (VkResult r = vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &cpci, nullptr, &k->pipeline); r != VK_SUCCESS) {
        *error = vk_error("vkCreateComputePipelines", r);
        return nullptr;
    }
    const VkDescriptorPoolSize pool_sizes[3] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, n},
                                                {VK_DESCRIPTOR_TYPE_SAMPLER, 1},
                                                {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, n_img > 0 ? n_img : 1}};
    VkDescriptorPoolCreateInfo dpci{};
    dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpci.maxSets = 1;
    dpci.poolSizeCount = n_img > 0 ? 3 : 1;
    dpci.pPoolSizes = pool_sizes;
    if (VkResult r = vkCreateDescriptorPool(dev, &dpci, nullptr, &k->pool); r != VK_SUCCESS) {
        *error = vk_error("vkCreateDescriptorPool", r);
        return nullptr;
    }
    VkDescriptorSetAllocateInfo dsai{};
    dsai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    dsai.descriptorPool = k->pool;
    dsai.descriptorSetCount = 1;
    dsai.pSetLayouts = &k->set_layout;
    if (VkResult r = vkAllocateDescriptorSets(dev, &dsai, &k->set); r != VK_SUCCESS) {
        *error = vk_error("vkAllocateDescriptorSets", r);
        return nullptr;
    }
    std::vector<VkDescriptorBufferInfo> infos(n);
    std::vector<VkWriteDescriptorSet> writes(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        infos[i] = {k->buffers[i], 0, VK_WHOLE_SIZE};
        writes[i] = {};
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstSet = k->set;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(dev, n, writes.data(), 0, nullptr);
    VkCommandPoolCreateInfo cpoolci{};
    cpoolci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    cpoolci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cpoolci.queueFamilyIndex = impl_->queue_family;
    if (VkResult r = vkCreateCommandPool(dev, &cpoolci, nullptr, &k->command_pool); r != VK_SUCCESS) {
        *error = vk_error("vkCreateCommandPool", r);
        return nullptr;
    }
    VkCommandBufferAllocateInfo cbai{};
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = k->command_pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    if (VkResult r = vkAllocateCommandBuffers(dev, &cbai, &k->command_buffer); r != VK_SUCCESS) {
        *error = vk_error("vkAllocateCommandBuffers", r);
        return nullptr;
    }
    if (n_img > 0 && !upload_images(*impl_, *k, images_in, n, error)) return nullptr;
    return std::unique_ptr<Kernel>(new Kernel(std::move(k)));
}

double Kernel::dispatch(std::uint32_t groups_x, std::string* error) {
    Impl& k = *impl_;
    VkCommandBuffer cb = k.command_buffer;
    vkResetCommandBuffer(cb, 0);
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if (VkResult r = vkBeginCommandBuffer(cb, &begin); r != VK_SUCCESS) {
        *error = vk_error("vkBeginCommandBuffer", r);
        return -1;
    }
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, k.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, k.pipeline_layout, 0, 1, &k.set, 0, nullptr);
    vkCmdDispatch(cb, groups_x, 1, 1);
    // Shader writes -> host reads of the mapped memory.
    VkMemoryBarrier barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr,
                         0, nullptr);
    if (VkResult r = vkEndCommandBuffer(cb); r != VK_SUCCESS) {
        *error = vk_error("vkEndCommandBuffer", r);
        return -1;
    }
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    const auto t0 = std::chrono::steady_clock::now();
    if (VkResult r = vkQueueSubmit(k.queue, 1, &submit, VK_NULL_HANDLE); r != VK_SUCCESS) {
        *error = vk_error("vkQueueSubmit", r);
        return -1;
    }
    if (VkResult r = vkQueueWaitIdle(k.queue); r != VK_SUCCESS) {
        *error = vk_error("vkQueueWaitIdle", r);
        return -1;
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

namespace {

// The "#define ZHC_X Nu" lines of zhc.hlsl from "---- encodings" up to ZHC_ENCODING_COUNT.
const std::map<std::string, int, std::less<>>& hlsl_defines() {
    static const std::map<std::string, int, std::less<>> m = [] {
        std::map<std::string, int, std::less<>> out;
        std::ifstream in(ZHC_RUNTIME_HLSL_PATH);
        bool section = false;
        for (std::string line; std::getline(in, line);) {
            if (line.find("---- encodings") != std::string::npos) section = true;
            std::istringstream words(line);
            std::string define, name, value;
            if (!section || !(words >> define >> name >> value) || define != "#define" || value.size() < 2 ||
                value.back() != 'u' || value.find_first_not_of("0123456789") != value.size() - 1)
                continue;
            out[name] = std::stoi(value);
            if (name == "ZHC_ENCODING_COUNT") break;
        }
        return out;
    }();
    return m;
}

}  // namespace

int hlsl_encoding(std::string_view name) {
    std::string macro = "ZHC_";
    for (char c : name) macro += static_cast<char>(c >= 'a' && c <= 'z' ? c - 'a' + 'A' : c);
    if (macro == "ZHC_ENCODING_COUNT") return -1;
    const auto it = hlsl_defines().find(macro);
    return it == hlsl_defines().end() ? -1 : it->second;
}

int hlsl_encoding_count() {
    const auto it = hlsl_defines().find("ZHC_ENCODING_COUNT");
    return it == hlsl_defines().end() ? -1 : it->second;
}

}  // namespace zhc::vk
