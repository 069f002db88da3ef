# ctest version.consistent: every file that states dmc's version says what dmc/version.h says
# (CMake read it into PROJECT_VERSION), and `dmc --version` prints it.
# Usage: cmake -DVERSION=X.Y.Z -DSOURCE_DIR=DIR [-DDMC=PATH] -P version_check.cmake
foreach(file web/package.json tools/viewer/package.json tests/browser/package.json)
  file(READ ${SOURCE_DIR}/${file} text)
  string(JSON stated GET "${text}" version)
  if(NOT stated STREQUAL VERSION)
    message(FATAL_ERROR "${file} says version ${stated}, dmc/version.h says ${VERSION}")
  endif()
endforeach()
if(DMC)
  execute_process(COMMAND ${DMC} --version OUTPUT_VARIABLE printed RESULT_VARIABLE status)
  if(NOT status EQUAL 0 OR NOT printed MATCHES "^dmc ${VERSION} ")
    message(FATAL_ERROR "dmc --version printed '${printed}' (exit ${status}), expected dmc ${VERSION}")
  endif()
endif()
message(STATUS "version ${VERSION} everywhere")
