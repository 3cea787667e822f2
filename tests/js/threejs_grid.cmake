# three.js LightProbeGrid files (formats/engines/threejs_grid.cpp): test_engine_file_threejs writes and
# reads OpenEXR itself (hostile files), and js.threejs_grid_files loads the files it writes with
# three.js's own EXRLoader / KTX2Loader in headless Chromium. Included from tests/CMakeLists.txt.
find_package(OpenEXR CONFIG REQUIRED)
target_link_libraries(test_engine_file_threejs PRIVATE OpenEXR::OpenEXR)
if(ZHC_NODE AND ZHC_NPM AND ZHC_CHROMIUM AND NOT ZHC_SANITIZE)
  add_test(NAME js.threejs_grid_files  # .exr / .ktx2 grid atlases through three.js's loaders and LightProbeGridWebGL vs the C++ entry
           COMMAND ${ZHC_NODE} "${ZHC_JS_DIR}/threejs_grid_files.mjs" "$<TARGET_FILE:test_engine_file_threejs>"
                   "${ZHC_JS_WORK}/threejs_grid_files" "${ZHC_CHROMIUM}")
  set_tests_properties(js.threejs_grid_files PROPERTIES FIXTURES_REQUIRED zhc_js TIMEOUT 600)
endif()
