# cmake -DSOURCE_DIR=... -DLAYERS=<build>/library_layers.cmake -P check_library_layers.cmake
cmake_minimum_required(VERSION 3.20)
# Fails naming each source line that includes a header of a project library
# its own library does not link (cmake/LibraryLayers.cmake): a header used
# without its library is a layer climbed the wrong way, or a link not said.
include(${LAYERS})
set(violations "")
foreach(module IN LISTS MODULES)
  file(GLOB_RECURSE sources RELATIVE ${SOURCE_DIR}
       ${SOURCE_DIR}/${module}/*.h ${SOURCE_DIR}/${module}/*.cpp)
  foreach(source IN LISTS sources)
    file(STRINGS ${SOURCE_DIR}/${source} includes REGEX "^#include \"[a-z]+/")
    foreach(line IN LISTS includes)
      string(REGEX MATCH "^#include \"([a-z]+)/" _ "${line}")
      set(used ${CMAKE_MATCH_1})
      if(used STREQUAL module OR NOT used IN_LIST MODULES)
        continue()
      endif()
      if(NOT used IN_LIST LINKS_${module})
        string(APPEND violations "  ${source}: ${line} (${module} does not link ${used})\n")
      endif()
    endforeach()
  endforeach()
endforeach()
if(violations)
  message(FATAL_ERROR "headers of libraries not linked:\n${violations}")
endif()
list(LENGTH MODULES count)
message(STATUS "${count} libraries include only what they link")
