# bench_runtime: runtime/zhc.hlsl compiled per encoding (glslangValidator -> spirv-opt -O,
# counted with spirv-dis) and timed on Mesa lavapipe. Included from bench/CMakeLists.txt before
# its per-benchmark loop: taken out of the generic list and defined here; left out without Vulkan.
list(FILTER ZHC_BENCH_SOURCES EXCLUDE REGEX "bench_runtime\\.cpp$")
find_package(Vulkan)
find_program(ZHC_GLSLANG glslangValidator)
find_program(ZHC_SPIRV_OPT spirv-opt)
find_program(ZHC_SPIRV_DIS spirv-dis)
include("${PROJECT_SOURCE_DIR}/tests/vk/vk_compute.cmake")
if(TARGET zhc_vk_compute AND ZHC_GLSLANG AND ZHC_SPIRV_OPT AND ZHC_SPIRV_DIS)
  add_executable(bench_runtime "${CMAKE_CURRENT_SOURCE_DIR}/bench_runtime.cpp")
  target_include_directories(bench_runtime PRIVATE "${PROJECT_SOURCE_DIR}")
  target_link_libraries(bench_runtime PRIVATE zhc_codec zhc_vk_compute zhc_warnings)
  set(ZHC_LVP_ICD_OR_EMPTY "")
  if(ZHC_LVP_ICD)
    set(ZHC_LVP_ICD_OR_EMPTY "${ZHC_LVP_ICD}")
  endif()
  target_compile_definitions(bench_runtime PRIVATE
    ZHC_GLSLANG="${ZHC_GLSLANG}" ZHC_SPIRV_OPT="${ZHC_SPIRV_OPT}" ZHC_SPIRV_DIS="${ZHC_SPIRV_DIS}"
    ZHC_RUNTIME_DIR="${PROJECT_SOURCE_DIR}/runtime" ZHC_LVP_ICD="${ZHC_LVP_ICD_OR_EMPTY}")
else()
  message(STATUS "Vulkan / glslangValidator / spirv-opt / spirv-dis not found: bench_runtime is not built")
endif()
