# Checks that every project #include respects the module layering (run by ctest as
# layering/includes_test; cmake -DSOURCE_DIR=<root> -P check_layering.cmake):
#   pipeline/  includes only pipeline/; a stage (lattice, calib, depth, direct, render, clip)
#              only itself, pipeline/core/ and pipeline/io/ (pipeline/run joins the stages;
#              a stage's tests and benchmarks may use the others)
#   drivers/   includes only drivers/, pipeline/core/ and pipeline/io/
#   capture/   includes only capture/, drivers/source/ (the frame-source interface), pipeline/core/
#              and pipeline/io/
#   sim/       includes only sim/, capture/, drivers/source/, pipeline/core/ and pipeline/io/
#   eval/      includes only eval/, pipeline/, capture/, sim/ and drivers/source/
#   device/    includes anything but eval/ and tools/ (the daemon is not a tool)
#   tools/     may include everything
# Test sources (*_test.*, *_benchmark.*, *test_util*) may also include tests/ helpers, and
# capture's tests sim/synthetic/ (generated scenes, where the real data lies).
# The CMake link lists enforce the same at link time; this names the offending line.
cmake_minimum_required(VERSION 3.20)
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "usage: cmake -DSOURCE_DIR=<project root> -P check_layering.cmake")
endif()

set(allowed_pipeline "pipeline/")
set(allowed_drivers "drivers/;pipeline/core/;pipeline/io/")
set(allowed_capture "capture/;drivers/source/;pipeline/core/;pipeline/io/")
set(allowed_sim "sim/;capture/;drivers/source/;pipeline/core/;pipeline/io/")
set(allowed_eval "eval/;pipeline/;capture/;sim/;drivers/source/")
set(test_allowed_capture "sim/synthetic/")
set(allowed_device "device/;pipeline/;capture/;sim/;drivers/;tests/")

# The stages do not include each other: each is a computation on core's types.
set(stages lattice calib depth direct render clip)

set(violations 0)
set(checked 0)
foreach(module pipeline drivers capture sim eval device)
  file(GLOB_RECURSE sources RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/${module}/*.h" "${SOURCE_DIR}/${module}/*.cc")
  foreach(source IN LISTS sources)
    math(EXPR checked "${checked} + 1")
    set(allowed ${allowed_${module}})
    if(module STREQUAL "pipeline" AND source MATCHES "^pipeline/([a-z_]+)/")
      set(stage "${CMAKE_MATCH_1}")
      # Tests and benchmarks may combine stages (a render benchmark that encodes its clip).
      if(stage IN_LIST stages AND NOT source MATCHES "(_test|_benchmark|test_util)[^/]*$")
        set(allowed "pipeline/${stage}/;pipeline/core/;pipeline/io/")
      endif()
    endif()
    if(source MATCHES "(_test|_benchmark|test_util)[^/]*$")
      list(APPEND allowed "tests/" ${test_allowed_${module}})
    endif()
    file(STRINGS "${SOURCE_DIR}/${source}" includes REGEX "^[ \t]*#[ \t]*include[ \t]+\"")
    foreach(line IN LISTS includes)
      string(REGEX REPLACE "^[^\"]*\"([^\"]+)\".*$" "\\1" header "${line}")
      set(ok FALSE)
      foreach(prefix IN LISTS allowed)
        string(FIND "${header}" "${prefix}" at)
        if(at EQUAL 0)
          set(ok TRUE)
        endif()
      endforeach()
      if(NOT ok)
        message(SEND_ERROR "${source}: includes \"${header}\"; ${module}/ may include only: ${allowed}")
        math(EXPR violations "${violations} + 1")
      endif()
    endforeach()
  endforeach()
endforeach()

if(violations GREATER 0)
  message(FATAL_ERROR "${violations} include(s) break the module layering")
endif()
string(REPLACE ";" ", " stage_names "${stages}")
message(STATUS "layering: ${checked} files of pipeline/, drivers/, capture/, sim/, eval/ and device/ include only what they may; the stages (${stage_names}) only themselves, pipeline/core/ and pipeline/io/")
