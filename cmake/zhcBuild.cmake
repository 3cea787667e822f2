# zhcBuild.cmake — zhc as a build step (installed with zhcConfig.cmake; docs/build-integration.md).
# find_package(zhc) defines the imported executable zhc::zhc and these functions. Each adds one
# add_custom_command(... DEPFILE ...): zhc writes the depfile (`--depfile`) naming every file the
# command read, so the build reruns it when the scene, an environment map behind it, a glTF buffer
# or image, or an EXR part changes, and never otherwise. Relative paths: SCENE/INPUT from
# CMAKE_CURRENT_SOURCE_DIR, OUTPUT/OUTPUT_PREFIX from CMAKE_CURRENT_BINARY_DIR. DEPFILE needs CMake
# 3.20 (Ninja and Makefile generators) and Ninja 1.10 for commands with several outputs.
#
#   zhc_add_bake(TARGET name SCENE scene.json|.gltf|.glb OUTPUT out.zhp|.json|.glb|.gltf [ALL] [ARGS ...])
#   zhc_add_lightmap(TARGET name INPUT sh.exr|"sh{i}.exr"|a.exr b.exr ... OUTPUT_PREFIX prefix
#                    [CONTAINER ktx2|dds] [ALL] [ARGS ...])
#
# TARGET is a custom target that builds the outputs (in `all` with ALL); ARGS go to the zhc command
# as they are (e.g. ARGS -r zh3_q16 --zstd 9).

# The checks both functions share (fn: the function's name, for the message).
macro(_zhc_check_call fn)
  if(Z_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "${fn}: unknown arguments ${Z_UNPARSED_ARGUMENTS}")
  endif()
  if(CMAKE_VERSION VERSION_LESS 3.20)
    message(FATAL_ERROR "${fn}: needs CMake 3.20 (add_custom_command DEPFILE)")
  endif()
endmacro()

# One step; the caller sets _zhc_outputs, _zhc_depfile, _zhc_depends and _zhc_command.
function(_zhc_add_step target all comment)
  # Paths in the depfile are absolute here; CMP0116 NEW (CMake 3.20) has CMake rewrite them for
  # Ninja, as it expects, whatever policy version the calling project asked for.
  cmake_policy(PUSH)
  cmake_policy(SET CMP0116 NEW)
  add_custom_command(OUTPUT ${_zhc_outputs}
                     COMMAND zhc::zhc ${_zhc_command} --depfile "${_zhc_depfile}"
                     DEPENDS ${_zhc_depends} "$<TARGET_FILE:zhc::zhc>"
                     DEPFILE "${_zhc_depfile}"
                     COMMENT "${comment}"
                     VERBATIM)
  cmake_policy(POP)
  if(all)
    add_custom_target(${target} ALL DEPENDS ${_zhc_outputs})
  else()
    add_custom_target(${target} DEPENDS ${_zhc_outputs})
  endif()
endfunction()

function(zhc_add_bake)
  cmake_parse_arguments(PARSE_ARGV 0 Z "ALL" "TARGET;SCENE;OUTPUT" "ARGS")
  if(NOT Z_TARGET OR NOT Z_SCENE OR NOT Z_OUTPUT)
    message(FATAL_ERROR "zhc_add_bake: TARGET, SCENE and OUTPUT are required")
  endif()
  _zhc_check_call(zhc_add_bake)
  get_filename_component(scene "${Z_SCENE}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  get_filename_component(output "${Z_OUTPUT}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
  set(_zhc_outputs "${output}")
  set(_zhc_depfile "${output}.d")
  set(_zhc_depends "${scene}")
  set(_zhc_command bake "${scene}" -o "${output}" --quiet ${Z_ARGS})
  _zhc_add_step(${Z_TARGET} "${Z_ALL}" "zhc bake ${Z_SCENE} -> ${Z_OUTPUT}")
endfunction()

function(zhc_add_lightmap)
  cmake_parse_arguments(PARSE_ARGV 0 Z "ALL" "TARGET;OUTPUT_PREFIX;CONTAINER" "INPUT;ARGS")
  if(NOT Z_TARGET OR NOT Z_INPUT OR NOT Z_OUTPUT_PREFIX)
    message(FATAL_ERROR "zhc_add_lightmap: TARGET, INPUT and OUTPUT_PREFIX are required")
  endif()
  _zhc_check_call(zhc_add_lightmap)
  if(NOT Z_CONTAINER)
    set(Z_CONTAINER ktx2)
  endif()
  if(NOT Z_CONTAINER MATCHES "^(ktx2|dds)$")
    message(FATAL_ERROR "zhc_add_lightmap: CONTAINER must be ktx2 or dds")
  endif()
  set(inputs)
  set(depends)
  foreach(in IN LISTS Z_INPUT)
    get_filename_component(abs "${in}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND inputs "${abs}")
    if(NOT in MATCHES "\\{i\\}")  # the parts of a {i} name are known to the depfile only
      list(APPEND depends "${abs}")
    endif()
  endforeach()
  get_filename_component(prefix "${Z_OUTPUT_PREFIX}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
  # The files `lightmap encode` writes: BC gives .iz/.d/.wa, an ASTC `--target` in ARGS .iz/.dwa (KTX2).
  set(planes iz d wa)
  list(FIND Z_ARGS --target t)
  if(t GREATER -1)
    math(EXPR t "${t} + 1")
    list(LENGTH Z_ARGS n)
    if(t LESS n)
      list(GET Z_ARGS ${t} target_kind)
      if(target_kind MATCHES "^astc")
        if(NOT Z_CONTAINER STREQUAL "ktx2")
          message(FATAL_ERROR "zhc_add_lightmap: ASTC targets are written as KTX2 only (CONTAINER ktx2)")
        endif()
        set(planes iz dwa)
      endif()
    endif()
  endif()
  set(_zhc_outputs)
  foreach(plane IN LISTS planes)
    list(APPEND _zhc_outputs "${prefix}.${plane}.${Z_CONTAINER}")
  endforeach()
  set(_zhc_depfile "${prefix}.lightmap.d")
  set(_zhc_depends ${depends})
  set(_zhc_command lightmap encode ${inputs} -o "${prefix}" --container ${Z_CONTAINER} ${Z_ARGS})
  string(REPLACE ";" "," plane_list "${planes}")
  _zhc_add_step(${Z_TARGET} "${Z_ALL}" "zhc lightmap encode -> ${Z_OUTPUT_PREFIX}.{${plane_list}}.${Z_CONTAINER}")
endfunction()
