# px_add_library(NAME SRCS a.cc b.cc DEPS px_core ...)
#   One module = one target; DEPS is the module's full set of allowed arrows.
# px_add_test(NAME module/x_test SRCS x_test.cc DEPS ...)
#   A GoogleTest binary registered with CTest under the given name.
# px_add_benchmark(NAME SRCS DEPS): into build/bench/; PX_BUILD_BENCHMARKS (ON by default) turns them off.
# Libraries and programs are unity builds when PX_UNITY_BUILD is on: most of a first build's time
# is spent parsing the same OpenCV, Eigen, Ceres and JSON headers, once per batch instead of once
# per source. File-local names must therefore be unique within a target.

set(PX_WARNINGS -Wall -Wextra -Wpedantic -Wshadow=local -Wno-missing-field-initializers)
if(PX_WERROR)
  list(APPEND PX_WARNINGS -Werror)
endif()

function(px_target_defaults target)
  target_compile_options(${target} PRIVATE ${PX_WARNINGS})
  target_include_directories(${target} PUBLIC ${PROJECT_SOURCE_DIR})
endfunction()

function(px_unity_build target)
  set_target_properties(${target} PROPERTIES UNITY_BUILD ${PX_UNITY_BUILD} UNITY_BUILD_BATCH_SIZE 8)
endfunction()

function(px_add_library name)
  cmake_parse_arguments(ARG "" "" "SRCS;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SRCS})
  px_target_defaults(${name})
  px_unity_build(${name})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
endfunction()

function(px_add_executable name)
  cmake_parse_arguments(ARG "" "" "SRCS;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SRCS})
  px_target_defaults(${name})
  px_unity_build(${name})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR})
endfunction()

function(px_add_test test_name)
  if(NOT PX_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "TIMEOUT" "SRCS;DEPS;LABELS" ${ARGN})
  string(REPLACE "/" "_" target ${test_name})
  add_executable(${target} ${ARG_SRCS})
  px_target_defaults(${target})
  target_link_libraries(${target} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gmock GTest::gtest_main)
  target_compile_definitions(${target} PRIVATE PX_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                               PX_BINARY_DIR="${PROJECT_BINARY_DIR}")
  add_test(NAME ${test_name} COMMAND ${target})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 600)
  endif()
  set_tests_properties(${test_name} PROPERTIES TIMEOUT ${ARG_TIMEOUT} LABELS "${ARG_LABELS}"
    ENVIRONMENT "PX_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
endfunction()

function(px_add_benchmark name)
  if(NOT PX_BUILD_BENCHMARKS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SRCS;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SRCS})
  px_target_defaults(${name})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} benchmark::benchmark benchmark::benchmark_main)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/bench)
endfunction()

# Adds each listed subdirectory that has a CMakeLists.txt (modules appear as issues land).
macro(px_add_module_dirs)
  foreach(dir ${ARGN})
    if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${dir}/CMakeLists.txt)
      add_subdirectory(${dir})
    endif()
  endforeach()
endmacro()
