# `cmake --install` puts zhc into a prefix as a library other projects build against:
#   include/zhc/codec.h, include/zhc/formats.h      umbrella headers (#include <zhc/codec.h>)
#   include/zhc/codec/*/*.h, include/zhc/formats/*/*.h  the public headers of docs/api.md, by domain folder
#   include/zhc/zhc_runtime.h                       the C99 runtime decoder (when runtime/ exists)
#   include/zhc/zhc_volume_layouts.hpp              GPU volume layouts over it (C++17)
#   lib/libzhc_codec.a, lib/libzhc_formats.a        static libraries
#   lib/cmake/zhc/zhcConfig.cmake                   find_package(zhc): targets zhc::codec, zhc::formats, zhc::zhc
#   lib/cmake/zhc/zhcBuild.cmake                    zhc_add_bake, zhc_add_lightmap (with bin/zhc; docs/build-integration.md)
#   lib/pkgconfig/zhc.pc                            pkg-config --static --cflags --libs zhc
#   share/zhc/runtime/                              runtime files (C header, GLSL, HLSL, web package)
#   bin/zhc                                         the command
# What was built decides what is installed: without ZHC_BUILD_FORMATS only zhc::codec, its headers
# and the runtime files; without ZHC_BUILD_CLI no bin/zhc.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(ZHC_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/zhc")

set(ZHC_INSTALLED_PARTS codec)
if(TARGET zhc_formats)
  list(APPEND ZHC_INSTALLED_PARTS formats)
endif()
foreach(part ${ZHC_INSTALLED_PARTS})
  foreach(h ${ZHC_PUBLIC_HEADERS_${part}})
    get_filename_component(_sub "${h}" DIRECTORY)  # the domain folder (probe, lightmap, io, ...)
    install(FILES "${PROJECT_SOURCE_DIR}/${part}/${h}" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/zhc/${part}/${_sub}")
  endforeach()
  install(FILES "${PROJECT_BINARY_DIR}/include/zhc/${part}.h" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/zhc")
endforeach()
# bc6h_encoder*.inl are compiled into the library, not an interface: not installed.

list(TRANSFORM ZHC_INSTALLED_PARTS PREPEND zhc_ OUTPUT_VARIABLE _libs)
install(TARGETS ${_libs} EXPORT zhcTargets
        ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
        INCLUDES DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
if(TARGET zhc)
  install(TARGETS zhc RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
endif()
install(EXPORT zhcTargets NAMESPACE zhc:: DESTINATION "${ZHC_CMAKE_DIR}")

if(EXISTS "${PROJECT_SOURCE_DIR}/runtime")
  install(DIRECTORY "${PROJECT_SOURCE_DIR}/runtime/" DESTINATION "${CMAKE_INSTALL_DATADIR}/zhc/runtime"
          PATTERN "CMakeLists.txt" EXCLUDE PATTERN "node_modules" EXCLUDE)
  if(EXISTS "${PROJECT_SOURCE_DIR}/runtime/zhc_runtime.h")
    install(FILES "${PROJECT_SOURCE_DIR}/runtime/zhc_runtime.h" "${PROJECT_SOURCE_DIR}/runtime/zhc_volume_layouts.hpp"
            DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}/zhc")
  endif()
endif()

# zhcConfig.cmake finds the third-party libraries zhc::formats links privately, when it is installed.
if(TARGET zhc_formats)
  set(ZHC_CONFIG_HAS_FORMATS 1)
else()
  set(ZHC_CONFIG_HAS_FORMATS 0)
endif()
# ... and defines zhc::zhc and the build-step helpers (zhcBuild.cmake) when bin/zhc is installed.
if(TARGET zhc)
  set(ZHC_CONFIG_HAS_CLI 1)
  install(FILES "${PROJECT_SOURCE_DIR}/cmake/zhcBuild.cmake" DESTINATION "${ZHC_CMAKE_DIR}")
else()
  set(ZHC_CONFIG_HAS_CLI 0)
endif()
configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/zhcConfig.cmake.in"
                              "${PROJECT_BINARY_DIR}/zhcConfig.cmake" INSTALL_DESTINATION "${ZHC_CMAKE_DIR}"
                              PATH_VARS CMAKE_INSTALL_BINDIR)
write_basic_package_version_file("${PROJECT_BINARY_DIR}/zhcConfigVersion.cmake" COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/zhcConfig.cmake" "${PROJECT_BINARY_DIR}/zhcConfigVersion.cmake"
        DESTINATION "${ZHC_CMAKE_DIR}")

# zhc.pc locates the prefix from its own folder (${pcfiledir}), so `cmake --install --prefix P`
# to any P gives a working file.
file(RELATIVE_PATH ZHC_PC_TO_PREFIX "/root/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/root")
string(REGEX REPLACE "/$" "" ZHC_PC_TO_PREFIX "${ZHC_PC_TO_PREFIX}")
if(TARGET zhc_formats)
  set(ZHC_PC_LIBS "-lzhc_formats -lzhc_codec")
  set(ZHC_PC_LIBS_PRIVATE "-lmeshoptimizer -lastcenc -lembree3")
  set(ZHC_PC_REQUIRES_PRIVATE "OpenEXR libzstd nlohmann_json draco tinygltf libpng libdeflate")
else()
  set(ZHC_PC_LIBS "-lzhc_codec")
  set(ZHC_PC_LIBS_PRIVATE "-lembree3")  # zhc::codec's bake traces with Embree 3 (no pkg-config file)
  set(ZHC_PC_REQUIRES_PRIVATE "")
endif()
configure_file("${PROJECT_SOURCE_DIR}/cmake/zhc.pc.in" "${PROJECT_BINARY_DIR}/zhc.pc" @ONLY)
install(FILES "${PROJECT_BINARY_DIR}/zhc.pc" DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
