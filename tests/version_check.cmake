# ctest version.consistent: every file that states dmc's version says what dmc/version.h says
# (CMake read it into PROJECT_VERSION): the package.json files, the spec's reference
# implementation line, and `dmc --version`.
# Usage: cmake -DVERSION=X.Y.Z -DSOURCE_DIR=DIR [-DDMC=PATH] -P version_check.cmake
foreach(file web/package.json tools/viewer/package.json tests/browser/package.json)
  file(READ ${SOURCE_DIR}/${file} text)
  string(JSON stated GET "${text}" version)
  if(NOT stated STREQUAL VERSION)
    message(FATAL_ERROR "${file} says version ${stated}, dmc/version.h says ${VERSION}")
  endif()
endforeach()
# The spec names its reference implementation by major.minor ("dmc 0.1").
file(STRINGS ${SOURCE_DIR}/bitstream-spec/dmc-format.md reference REGEX "^\\| Reference implementation \\|")
string(REGEX MATCH "^[0-9]+\\.[0-9]+" major_minor "${VERSION}")
if(NOT reference MATCHES "\\| dmc ${major_minor} ")
  message(FATAL_ERROR "the spec's reference implementation line '${reference}' is not dmc ${major_minor}")
endif()
if(DMC)
  execute_process(COMMAND ${DMC} --version OUTPUT_VARIABLE printed RESULT_VARIABLE status)
  if(NOT status EQUAL 0 OR NOT printed MATCHES "^dmc ${VERSION} ")
    message(FATAL_ERROR "dmc --version printed '${printed}' (exit ${status}), expected dmc ${VERSION}")
  endif()
endif()
message(STATUS "version ${VERSION} everywhere")
