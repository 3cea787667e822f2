# Library and CLI sources are listed explicitly in each folder's CMakeLists.txt (a build
# that says what it compiles). zhc_check_sources_listed(DIR LISTED...) then fails the configure
# step, naming the file, when DIR holds a .cpp the list lacks (a file added without listing it, or
# a merge that brought one) or the list names a missing one. The glob here only checks the list;
# it never decides what is compiled. Sources live in domain subfolders (codec/probe/, formats/io/,
# ...) and are listed with that relative path. (tests/, bench/ and fuzz/ keep their test_*/bench_*/fuzz_*
# auto-registration.)
function(zhc_check_sources_listed dir)
  file(GLOB_RECURSE _present RELATIVE "${dir}" "${dir}/*.cpp")
  set(_listed "")
  foreach(src ${ARGN})
    set(_name "${src}")  # relative to DIR, e.g. probe/zh3.cpp
    list(APPEND _listed "${_name}")
    if(NOT EXISTS "${dir}/${_name}")
      message(FATAL_ERROR "${dir}/${_name} is listed in ${dir}/CMakeLists.txt but does not exist")
    endif()
  endforeach()
  foreach(f ${_present})
    if(NOT f IN_LIST _listed)
      message(FATAL_ERROR "${dir}/${f} is not listed in ${dir}/CMakeLists.txt: add it to the source list")
    endif()
  endforeach()
endfunction()
