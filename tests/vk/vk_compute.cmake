# zhc_vk_compute: the headless Vulkan compute set-up shared by tests/test_runtime_vk.cpp and
# bench/bench_runtime.cpp. Included by tests/vk/CMakeLists.txt and bench/CMakeLists.txt after they
# ran find_package(Vulkan); defines the target once (when Vulkan was found).
if(NOT TARGET zhc_vk_compute AND TARGET Vulkan::Vulkan)
  add_library(zhc_vk_compute STATIC "${CMAKE_CURRENT_LIST_DIR}/vk_compute.cpp")
  target_include_directories(zhc_vk_compute PUBLIC "${CMAKE_CURRENT_LIST_DIR}")
  target_link_libraries(zhc_vk_compute PUBLIC Vulkan::Vulkan PRIVATE zhc_warnings)
  # hlsl_encoding() reads the encoding ids from the runtime's source.
  target_compile_definitions(zhc_vk_compute PRIVATE ZHC_RUNTIME_HLSL_PATH="${CMAKE_CURRENT_LIST_DIR}/../../runtime/zhc.hlsl")
endif()

# Mesa's CPU Vulkan driver (lavapipe): its ICD manifest, forced by the test and the benchmark.
if(NOT ZHC_LVP_ICD)
  find_file(ZHC_LVP_ICD NAMES "lvp_icd.${CMAKE_SYSTEM_PROCESSOR}.json" lvp_icd.x86_64.json lvp_icd.json
            PATHS /usr/share/vulkan/icd.d /usr/local/share/vulkan/icd.d /etc/vulkan/icd.d NO_DEFAULT_PATH)
endif()
