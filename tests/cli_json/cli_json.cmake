# --- JSON outputs: every `zhc ... --json` validates against docs/schema/<verb>.schema.json.
# Debian python3-jsonschema, run by the system interpreter (/usr/bin/python3: a pyenv or venv
# python3 earlier on PATH would not see the Debian module).
set(ZHC_SYSTEM_PYTHON /usr/bin/python3)
execute_process(COMMAND ${ZHC_SYSTEM_PYTHON} -c "import jsonschema" RESULT_VARIABLE zhc_jsonschema_missing
                OUTPUT_QUIET ERROR_QUIET)
if(zhc_jsonschema_missing)
  if(ZHC_REQUIRE_MESA_TEST)
    message(FATAL_ERROR "python3-jsonschema not found for ${ZHC_SYSTEM_PYTHON}: cli.json_schemas needs it (install: python3-jsonschema)")
  endif()
  message(STATUS "python3-jsonschema not found: cli.json_schemas skipped (bash scripts/setup.sh --test installs it)")
else()
  add_test(NAME cli.json_schemas
           COMMAND ${ZHC_SYSTEM_PYTHON} "${CMAKE_CURRENT_LIST_DIR}/check_schemas.py" "$<TARGET_FILE:zhc>"
                   "${PROJECT_SOURCE_DIR}/docs/schema" "${ZHC_ENVMAP_DIR}/studio.exr"
                   "${CMAKE_CURRENT_BINARY_DIR}/cli_json" "${CMAKE_CURRENT_SOURCE_DIR}/data/gltf/gt_list.glb")
  set_tests_properties(cli.json_schemas PROPERTIES TIMEOUT 600)
endif()
