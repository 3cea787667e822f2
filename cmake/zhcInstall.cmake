# `cmake --install` puts zhc into a prefix as a library other projects build against:
#   include/zhc/codec.h, include/zhc/formats.h      umbrella headers (#include <zhc/codec.h>)
#   include/zhc/codec/*/*.h, include/zhc/formats/*/*.h  the public headers, by domain folder
#   include/zhc/zhc_runtime.h                       the C99 runtime decoder (when runtime/ exists)
#   include/zhc/zhc_volume_layouts.hpp              GPU volume layouts over it (C++17)
#   lib/libzhc_codec.a, lib/libzhc_formats.a        static libraries
#   lib/cmake/zhc/zhcConfig.cmake                   find_package(zhc): targets zhc::codec, zhc::formats, zhc::zhc
#   lib/cmake/zhc/zhcBuild.cmake                    zhc_add_bake, zhc_add_lightmap (docs/build-integration.md)
#   lib/pkgconfig/zhc.pc                            pkg-config --static --cflags --libs zhc
#   share/zhc/runtime/                              runtime files (C header, GLSL, HLSL, web package)
#   bin/zhc                                         the command
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(ZHC_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/zhc")

# Public headers: every header of codec/ and formats/ except those whose first line says "internal to
# codec/" and the internal ones that include a third-party library's headers (third-party libraries stay at the edge, out of codec/: README.md "Layout"; e.g.
# formats/io/exr_memory.h). The umbrella headers include them all, so a new header needs no edit here.
foreach(part codec formats)
  file(GLOB_RECURSE _headers RELATIVE "${PROJECT_SOURCE_DIR}/${part}" CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/${part}/*.h")
  list(SORT _headers)
  set(_umbrella "// zhc/${part}.h — umbrella header of zhc_${part} (generated at configure time).\n#pragma once\n")
  foreach(h ${_headers})
    file(STRINGS "${PROJECT_SOURCE_DIR}/${part}/${h}" _third_party
         REGEX "^#include <(Imf|Iex|Imath|tiny_gltf|draco/|zstd|meshoptimizer|stb_|CLI/)")
    # Headers whose first line says "internal to codec/" (or formats/) are implementation details.
    file(STRINGS "${PROJECT_SOURCE_DIR}/${part}/${h}" _internal LIMIT_COUNT 1 REGEX "internal to (codec|formats)/")
    if(_third_party OR _internal)
      continue()
    endif()
    string(APPEND _umbrella "#include \"${part}/${h}\"\n")
    get_filename_component(_sub "${h}" DIRECTORY)  # the domain folder (probe, lightmap, io, ...)
    install(FILES "${PROJECT_SOURCE_DIR}/${part}/${h}" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/zhc/${part}/${_sub}")
  endforeach()
  file(GENERATE OUTPUT "${PROJECT_BINARY_DIR}/include/zhc/${part}.h" CONTENT "${_umbrella}")
  install(FILES "${PROJECT_BINARY_DIR}/include/zhc/${part}.h" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/zhc")
endforeach()
# bc6h_encoder*.inl are compiled into the library, not an interface: not installed.

install(TARGETS zhc_codec zhc_formats EXPORT zhcTargets
        ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
        INCLUDES DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
install(TARGETS zhc RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
install(EXPORT zhcTargets NAMESPACE zhc:: DESTINATION "${ZHC_CMAKE_DIR}")

if(EXISTS "${PROJECT_SOURCE_DIR}/runtime")
  install(DIRECTORY "${PROJECT_SOURCE_DIR}/runtime/" DESTINATION "${CMAKE_INSTALL_DATADIR}/zhc/runtime"
          PATTERN "CMakeLists.txt" EXCLUDE PATTERN "node_modules" EXCLUDE)
  if(EXISTS "${PROJECT_SOURCE_DIR}/runtime/zhc_runtime.h")
    install(FILES "${PROJECT_SOURCE_DIR}/runtime/zhc_runtime.h" "${PROJECT_SOURCE_DIR}/runtime/zhc_volume_layouts.hpp"
            DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/zhc")
  endif()
endif()

configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/zhcConfig.cmake.in"
                              "${PROJECT_BINARY_DIR}/zhcConfig.cmake" INSTALL_DESTINATION "${ZHC_CMAKE_DIR}"
                              PATH_VARS CMAKE_INSTALL_BINDIR)
write_basic_package_version_file("${PROJECT_BINARY_DIR}/zhcConfigVersion.cmake" COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/zhcConfig.cmake" "${PROJECT_BINARY_DIR}/zhcConfigVersion.cmake"
              "${PROJECT_SOURCE_DIR}/cmake/zhcBuild.cmake" DESTINATION "${ZHC_CMAKE_DIR}")

# zhc.pc locates the prefix from its own folder (${pcfiledir}), so `cmake --install --prefix P`
# to any P gives a working file.
file(RELATIVE_PATH ZHC_PC_TO_PREFIX "/root/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/root")
string(REGEX REPLACE "/$" "" ZHC_PC_TO_PREFIX "${ZHC_PC_TO_PREFIX}")
configure_file("${PROJECT_SOURCE_DIR}/cmake/zhc.pc.in" "${PROJECT_BINARY_DIR}/zhc.pc" @ONLY)
install(FILES "${PROJECT_BINARY_DIR}/zhc.pc" DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
