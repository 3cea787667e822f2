# test_exr_colour: EXR chromaticities, luminance/chroma, data vs display window and
# zhc info's EXR fields, on files written by OpenEXR's API and by Debian's exrstdattr (package
# openexr, scripts/packages-test.txt): without it the exrstdattr cases are left out.
target_link_libraries(test_exr_colour PRIVATE OpenEXR::OpenEXR)
find_program(ZHC_TOOL_EXRSTDATTR exrstdattr PATHS /usr/bin NO_DEFAULT_PATH)
find_program(ZHC_TOOL_EXRSTDATTR exrstdattr)
if(ZHC_TOOL_EXRSTDATTR)
  target_compile_definitions(test_exr_colour PRIVATE ZHC_TOOL_EXRSTDATTR="${ZHC_TOOL_EXRSTDATTR}")
else()
  message(STATUS "exrstdattr not found: test_exr_colour skips the files it would write (scripts/packages-test.txt)")
endif()
