# arview_module(<name> [DEPS <targets...>])
#
# One library per top-level folder: every *.cpp in the folder except *_test.cpp and
# bench_*.cpp goes into the library `arview_<name>` (alias arview::<name>).
# *_test.cpp files form one GoogleTest binary `<name>_tests`, run by ctest.
# bench_*.cpp files form the Google Benchmark binary `bench_<name>`.
function(arview_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;TEST_DEPS" ${ARGN})
  file(GLOB all_sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  set(lib_sources "")
  set(test_sources "")
  set(bench_sources "")
  foreach(src IN LISTS all_sources)
    get_filename_component(base ${src} NAME)
    if(base MATCHES "_test\\.cpp$")
      list(APPEND test_sources ${src})
    elseif(base MATCHES "^bench_.*\\.cpp$")
      list(APPEND bench_sources ${src})
    else()
      list(APPEND lib_sources ${src})
    endif()
  endforeach()

  if(lib_sources)
    add_library(arview_${name} STATIC ${lib_sources})
    target_include_directories(arview_${name} PUBLIC ${PROJECT_SOURCE_DIR})
    target_link_libraries(arview_${name} PUBLIC ${ARG_DEPS})
  else()
    # A module whose code is all headers so far.
    add_library(arview_${name} INTERFACE)
    target_include_directories(arview_${name} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(arview_${name} INTERFACE ${ARG_DEPS})
  endif()
  add_library(arview::${name} ALIAS arview_${name})

  if(ARVIEW_BUILD_TESTS AND test_sources)
    add_executable(${name}_tests ${test_sources})
    target_link_libraries(${name}_tests PRIVATE arview_${name} arview_testing ${ARG_TEST_DEPS} GTest::gtest GTest::gtest_main GTest::gmock)
    gtest_discover_tests(${name}_tests
      WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
      PROPERTIES ENVIRONMENT "ARVIEW_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
      DISCOVERY_TIMEOUT 60)
  endif()

  if(ARVIEW_BUILD_BENCHMARKS AND bench_sources)
    add_executable(bench_${name} ${bench_sources})
    target_link_libraries(bench_${name} PRIVATE arview_${name} arview_testing benchmark::benchmark)
  endif()
endfunction()
