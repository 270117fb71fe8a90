# _arview_label_discovered(<test target> <labels> <tsan regex> <serial regex>)
#
# Labels the tests that the last gtest_discover_tests call of <test target> found, once ctest
# has read them: <labels> (a list: gtest_discover_tests (CMake 3.25) splits a list-valued
# property) on each, and `tsan` besides on those whose name matches <tsan regex> (empty: none).
# Tests labelled `slurm` also share the RESOURCE_LOCK arview_slurm_cluster; those whose name
# matches <serial regex> (empty: none) run alone (RUN_SERIAL).
function(_arview_label_discovered target labels tsan_regex serial_regex)
  get_property(counter TARGET ${target} PROPERTY CTEST_DISCOVERED_TEST_COUNTER)
  set(tests_file "${CMAKE_CURRENT_BINARY_DIR}/${target}[${counter}]_tests.cmake")
  set(labels_script "${CMAKE_CURRENT_BINARY_DIR}/${target}[${counter}]_labels.cmake")
  file(WRITE "${labels_script}" "
if(EXISTS \"${tests_file}\")
  file(STRINGS \"${tests_file}\" lines REGEX \"^add_test\\\\(\")
  foreach(line IN LISTS lines)
    if(NOT line MATCHES \"^add_test\\\\(\\\\[=\\\\[([^]]*)\\\\]=\\\\]\")
      continue()
    endif()
    set(name \"\${CMAKE_MATCH_1}\")
    set(labels \"${labels}\")
    if(NOT \"${tsan_regex}\" STREQUAL \"\" AND name MATCHES \"${tsan_regex}\")
      list(APPEND labels tsan)
    endif()
    if(labels)
      set_tests_properties(\"\${name}\" PROPERTIES LABELS \"\${labels}\")
    endif()
    if(NOT \"${serial_regex}\" STREQUAL \"\" AND name MATCHES \"${serial_regex}\")
      set_tests_properties(\"\${name}\" PROPERTIES RUN_SERIAL TRUE)
    endif()
    # The Slurm tests share one cluster, and one of them kills its node: never two at once.
    list(FIND labels slurm slurm_index)
    if(NOT slurm_index EQUAL -1)
      set_tests_properties(\"\${name}\" PROPERTIES RESOURCE_LOCK arview_slurm_cluster)
    endif()
  endforeach()
endif()
")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES "${labels_script}")
endfunction()

# The regular expression a test name matches when a gtest filter ("A.*:B.C?") selects it.
function(_arview_gtest_filter_regex filter out)
  set(regex "")
  if(filter)
    string(REPLACE "." "\\\\." regex "${filter}")
    string(REPLACE "*" ".*" regex "${regex}")
    string(REPLACE "?" "." regex "${regex}")
    string(REPLACE ":" "|" regex "${regex}")
    set(regex "^(${regex})$")
  endif()
  set(${out} "${regex}" PARENT_SCOPE)
endfunction()

# arview_discover_tests(<test target> [DATA <gtest filter>] [SLOW_DATA <gtest filter>]
#                       [SLOW <gtest filter>] [SLURM <gtest filter>] [TSAN <gtest filter>] [SERIAL <gtest filter>]
#                       [ENVIRONMENT <VAR=value>])
#
# Registers a GoogleTest binary's tests with ctest, labelled so that `ctest -LE slow` is the
# quick loop and `ctest -L data` runs what reads ../shared/data:
#   DATA       tests that read ../shared/data             label `data`
#   SLOW_DATA  tests that read it and run over 30 s        labels `data` and `slow`
#   SLOW       tests over 30 s that read no shared data    label `slow`
#   SLURM      tests that submit jobs to the Slurm cluster of scripts/slurm-local.sh (and read
#              the data, over 30 s)                       labels `data`, `slow` and `slurm`
# Filters are gtest patterns joined by ':' (e.g. "TempleMapTest.*:Import.Fox"), disjoint; every
# other test of the binary is registered without a label. Each group is one gtest_discover_tests
# call with a TEST_FILTER, so a binary can mix quick and slow tests.
#   TSAN       tests that run threads of ours, whichever group they are in: label `tsan` besides,
#              run under ThreadSanitizer by `ctest --preset tsan` (scripts/test.sh --tsan)
#   SERIAL     tests that hold something to the wall clock and fail when starved (a sound
#              player's deadlines), whichever group they are in: run alone (RUN_SERIAL)
function(arview_discover_tests target)
  cmake_parse_arguments(ARG "" "DATA;SLOW_DATA;SLOW;SLURM;TSAN;SERIAL;ENVIRONMENT" "" ${ARGN})
  _arview_gtest_filter_regex("${ARG_TSAN}" tsan_regex)
  _arview_gtest_filter_regex("${ARG_SERIAL}" serial_regex)
  # One variable: gtest_discover_tests (CMake 3.25) would split a list of them.
  set(environment "ARVIEW_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
  if(ARG_ENVIRONMENT)
    set(environment "${ARG_ENVIRONMENT}")
  endif()
  set(labelled "")
  foreach(group DATA SLOW_DATA SLOW SLURM)
    if(ARG_${group})
      list(APPEND labelled ${ARG_${group}})
    endif()
  endforeach()
  list(JOIN labelled ":" labelled)
  set(rest_filter "")
  if(labelled)
    set(rest_filter TEST_FILTER "-${labelled}")
  endif()
  gtest_discover_tests(${target} ${rest_filter}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES ENVIRONMENT "${environment}"
    DISCOVERY_TIMEOUT 60)
  if(tsan_regex OR serial_regex)
    _arview_label_discovered(${target} "" "${tsan_regex}" "${serial_regex}")
  endif()
  foreach(group DATA SLOW_DATA SLOW SLURM)
    if(NOT ARG_${group})
      continue()
    endif()
    set(labels data)
    if(group STREQUAL "SLOW_DATA")
      set(labels data slow)
    elseif(group STREQUAL "SLOW")
      set(labels slow)
    elseif(group STREQUAL "SLURM")
      set(labels data slow slurm)
    endif()
    gtest_discover_tests(${target} TEST_FILTER "${ARG_${group}}"
      WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
      PROPERTIES ENVIRONMENT "${environment}"
      DISCOVERY_TIMEOUT 60)
    # Set by a ctest script that runs after the discovered tests are added: one list-valued
    # property would be split by gtest_discover_tests.
    _arview_label_discovered(${target} "${labels}" "${tsan_regex}" "${serial_regex}")
  endforeach()
endfunction()

# arview_compile_as_tests(<sources...>)
#
# GoogleTest sources compile at -O1 in the release build (the last -O on GCC's command line
# wins over CMAKE_CXX_FLAGS_RELEASE's -O2): what they test is in the libraries, at -O2, and the
# test sources (GoogleTest's macros, Eigen and OpenCV inlined into checks) took a fifth longer to
# compile at -O2 for no run time that matters (docs/architecture.md, "Build time"). The asan
# and tsan presets build everything at -O1 already; benchmarks stay at -O2.
function(arview_compile_as_tests)
  if(CMAKE_BUILD_TYPE STREQUAL "Release")
    set_source_files_properties(${ARGN} PROPERTIES COMPILE_OPTIONS "-O1")
  endif()
endfunction()

# arview_module(<name> [DEPS <targets...>] [TEST_DEPS <targets...>] [BENCH_DEPS <targets...>]
#               [DATA <filter>] [SLOW_DATA <filter>] [SLOW <filter>] [SLURM <filter>] [TSAN <filter>]
#               [SERIAL <filter>])
#
# One library per top-level folder: every *.cpp in the folder except *_test.cpp and
# bench_*.cpp goes into the library `arview_<name>` (alias arview::<name>).
# *_test.cpp files form one GoogleTest binary `<name>_tests`, run by ctest (DATA, SLOW_DATA,
# SLOW, SLURM: see arview_discover_tests).
# bench_*.cpp files form the Google Benchmark binary `bench_<name>`.
# TEST_DEPS / BENCH_DEPS: what the tests / benchmarks link beyond the library (e.g. a runtime
# library's tests loading assets through its authoring library).
function(arview_module name)
  cmake_parse_arguments(ARG "" "DATA;SLOW_DATA;SLOW;SLURM;TSAN;SERIAL" "DEPS;TEST_DEPS;BENCH_DEPS" ${ARGN})
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
    arview_compile_as_tests(${test_sources})
    add_executable(${name}_tests ${test_sources})
    target_link_libraries(${name}_tests PRIVATE arview_${name} arview_testing ${ARG_TEST_DEPS} GTest::gtest GTest::gtest_main GTest::gmock)
    arview_discover_tests(${name}_tests DATA "${ARG_DATA}" SLOW_DATA "${ARG_SLOW_DATA}" SLOW "${ARG_SLOW}"
                          SLURM "${ARG_SLURM}" TSAN "${ARG_TSAN}" SERIAL "${ARG_SERIAL}")
  endif()

  if(ARVIEW_BUILD_BENCHMARKS AND bench_sources)
    add_executable(bench_${name} ${bench_sources})
    target_link_libraries(bench_${name} PRIVATE arview_${name} arview_testing ${ARG_BENCH_DEPS} benchmark::benchmark)
  endif()
endfunction()
