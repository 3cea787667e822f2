# test_real_world: files written by other programs. It writes EXRs with OpenEXR's own
# API and runs Debian's OpenEXR tools (package openexr) and ImageMagick (package imagemagick).
# test_real_world_hostile: the hostile variants (trailing bytes, memory, .hdr orientations, JSON depth).
find_package(OpenEXR CONFIG REQUIRED)
target_link_libraries(test_real_world PRIVATE OpenEXR::OpenEXR)
target_link_libraries(test_real_world_hostile PRIVATE OpenEXR::OpenEXR)
foreach(tool exrenvmap exrmultipart exrmaketiled convert)
  string(TOUPPER "${tool}" upper)
  find_program(ZHC_TOOL_${upper} ${tool} PATHS /usr/bin NO_DEFAULT_PATH)
  find_program(ZHC_TOOL_${upper} ${tool})
  if(ZHC_TOOL_${upper})
    target_compile_definitions(test_real_world PRIVATE ZHC_TOOL_${upper}="${ZHC_TOOL_${upper}}")
    target_compile_definitions(test_real_world_hostile PRIVATE ZHC_TOOL_${upper}="${ZHC_TOOL_${upper}}")
  else()
    message(STATUS "${tool} not found: test_real_world skips the files it would write (scripts/packages-test.txt)")
  endif()
endforeach()
