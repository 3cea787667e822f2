# runtime/zhc.glsl.
# test_runtime_gl runs it as a compute shader on Mesa llvmpipe (EGL + desktop GL 4.5 core), like
# test_mesa_bc; it is built only when EGL/GL were found (tests/CMakeLists.txt filters it out
# otherwise, and ZHC_REQUIRE_MESA_TEST makes that an error).
if(TARGET test_runtime_gl)
  target_link_libraries(test_runtime_gl PRIVATE OpenGL::OpenGL OpenGL::EGL zhc_runtime zhc_tetra)  # zhc_volume_*: the reference; zhc_tetra: scattered probes' tetrahedra
  target_compile_definitions(test_runtime_gl PRIVATE ZHC_RUNTIME_GLSL_PATH="${PROJECT_SOURCE_DIR}/runtime/zhc.glsl")
  # Mesa/LLVM allocations live until exit (see gl/CMakeLists.txt): no leak checking here only.
  gtest_discover_tests(test_runtime_gl DISCOVERY_TIMEOUT 60
    PROPERTIES TIMEOUT 1200 ENVIRONMENT "ASAN_OPTIONS=detect_leaks=0:abort_on_error=1")
endif()
# The same file must compile as GLSL ES 3.10 and GLSL 4.50, compute and fragment stages
# (glslangValidator from glslang-tools; scripts/packages-test.txt).
find_program(ZHC_GLSLANG_VALIDATOR glslangValidator)
if(ZHC_GLSLANG_VALIDATOR)
  foreach(version "310 es" "450")
    foreach(stage comp frag)
      string(REPLACE " " "" tag "${version}")
      add_test(NAME glsl.zhc_${tag}_${stage}
        COMMAND ${CMAKE_COMMAND} -DVALIDATOR=${ZHC_GLSLANG_VALIDATOR} -DVERSION=${version} -DSTAGE=${stage}
          -DLIBRARY=${PROJECT_SOURCE_DIR}/runtime/zhc.glsl -DOUT_DIR=${CMAKE_CURRENT_BINARY_DIR}/glsl
          -P ${CMAKE_CURRENT_SOURCE_DIR}/gl/check_glsl.cmake)
    endforeach()
  endforeach()
elseif(ZHC_REQUIRE_MESA_TEST)
  message(FATAL_ERROR "glslangValidator not found (install: glslang-tools)")
else()
  message(STATUS "glslangValidator not found: runtime/zhc.glsl compile checks skipped")
endif()
