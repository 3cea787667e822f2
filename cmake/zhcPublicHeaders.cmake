# zhc's public headers (docs/api.md "Public headers") and the umbrella headers over them.
#
# Public headers: the deliberate set of docs/api.md, nothing else (internal helpers such as
# formats/io/le_bytes.h, report/raster.h or io/json_depth.h stay in the source tree). Stable
# headers keep their API within a minor version; experimental ones say so in their first comment
# and may change. tests/install/run.sh checks that the prefix holds exactly the headers docs/api.md
# lists and that each compiles on its own against the prefix.
set(ZHC_PUBLIC_HEADERS_codec
  status.h sh/sh.h sh/cubemap.h
  probe/codec.h probe/probe_set.h probe/quantize.h probe/dering.h probe/zh3.h
  lightmap/irradz.h lightmap/lightmap.h lightmap/bc6h.h lightmap/bc45.h
  # experimental
  bake/scene.h bake/sky.h bake/occluders.h bake/transport.h bake/leak_planes.h audit/audit.h audit/audit_run.h audit/benchmark.h audit/choice.h)
set(ZHC_PUBLIC_HEADERS_formats
  io/file_io.h envmap/envmap.h envmap/envmap_cube.h probes/probe_file.h probes/gltf_probes.h
  lightmap/ktx2.h lightmap/dds.h lightmap/lightmap_exr.h
  # experimental
  lightmap/astc.h lightmap/lightmap_stream.h scene/scene_json.h scene/scene_gltf.h)

# zhc_umbrella_header(part target): generates <build>/include/zhc/<part>.h including every public
# header of the part, and puts it on the target's include path, so a consumer writes
# #include <zhc/codec.h> whether it uses an installed zhc or adds zhc with add_subdirectory.
function(zhc_umbrella_header part target)
  set(_umbrella "// zhc/${part}.h — umbrella header of zhc_${part}: its public headers (docs/api.md).\n#pragma once\n")
  foreach(h ${ZHC_PUBLIC_HEADERS_${part}})
    if(NOT EXISTS "${PROJECT_SOURCE_DIR}/${part}/${h}")
      message(FATAL_ERROR "cmake/zhcPublicHeaders.cmake: public header ${part}/${h} does not exist")
    endif()
    string(APPEND _umbrella "#include \"${part}/${h}\"\n")
  endforeach()
  file(GENERATE OUTPUT "${PROJECT_BINARY_DIR}/include/zhc/${part}.h" CONTENT "${_umbrella}")
  target_include_directories(${target} PUBLIC "$<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/include>")
endfunction()
