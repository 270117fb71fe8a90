# The architecture's boundaries (docs/architecture.md, "Boundaries"), checked on the sources:
#
#   1. A module includes only modules below it in ARVIEW_LAYERS (and itself). Tests (*_test.cpp),
#      benchmarks (bench_*.cpp) and test helpers (test_*.h) may use more: their TEST_DEPS.
#   2. The per-frame libraries (ARVIEW_RUNTIME_MODULES) include nothing of anim_authoring/, and
#      (arview_check_runtime_links, at configure time) do not link it, directly or through
#      another library.
#
# Included by the top-level CMakeLists.txt, which calls both checks at configure time, and run as
# a script by the ctest test `architecture.boundaries`:
#   cmake -DARVIEW_SOURCE_DIR=<checkout> -P cmake/ArviewBoundaries.cmake
# A violation fails with one line per offending #include: file:line, the include, and the rule.

# Bottom to top: "module:layer". A module may include a module of a lower layer only.
set(ARVIEW_LAYERS
  base:0
  calib:1 anim:1 speech:1 audio:1 listen:1 dialogue:1
  recordings:2 map:2 anim_authoring:2 room:2
  mapping:3 tracker:3 figure:3 render:3
  synth:4 video:4
  app/pipeline:5 app/placement:5
  app/session:6
  app/view:7 app/demo:7
  app/cli:8)
# The per-frame path: it runs every frame and must not carry the offline authoring library
# (Assimp, yaml-cpp, the scene reader) with it.
set(ARVIEW_RUNTIME_MODULES anim room render video app/pipeline)

function(arview_layer_of module out)
  set(${out} "" PARENT_SCOPE)
  foreach(entry IN LISTS ARVIEW_LAYERS)
    string(REPLACE ":" ";" pair "${entry}")
    list(GET pair 0 name)
    list(GET pair 1 layer)
    if(name STREQUAL module)
      set(${out} ${layer} PARENT_SCOPE)
      return()
    endif()
  endforeach()
endfunction()

# The module an include path names: "app/pipeline/x.h" → app/pipeline, "render/x.h" → render.
function(arview_module_of_include path out)
  set(${out} "" PARENT_SCOPE)
  if(path MATCHES "^(app/[a-z_]+)/")
    set(${out} ${CMAKE_MATCH_1} PARENT_SCOPE)
  elseif(path MATCHES "^([a-z_]+)/")
    set(${out} ${CMAKE_MATCH_1} PARENT_SCOPE)
  endif()
endfunction()

# Appends one line per violation in `module`'s library sources to the list named `out_list`.
function(arview_check_module_includes source_dir module out_list)
  arview_layer_of(${module} layer)
  list(FIND ARVIEW_RUNTIME_MODULES ${module} runtime_index)
  file(GLOB sources RELATIVE ${source_dir} ${source_dir}/${module}/*.h ${source_dir}/${module}/*.cpp)
  set(found ${${out_list}})
  foreach(source IN LISTS sources)
    get_filename_component(name ${source} NAME)
    if(name MATCHES "_test\\.cpp$" OR name MATCHES "^bench_" OR name MATCHES "^test_")
      continue()
    endif()
    file(STRINGS ${source_dir}/${source} lines)
    set(line_number 0)
    foreach(line IN LISTS lines)
      math(EXPR line_number "${line_number} + 1")
      if(NOT line MATCHES "^[ \t]*#[ \t]*include[ \t]+\"([^\"]+)\"")
        continue()
      endif()
      set(included ${CMAKE_MATCH_1})
      arview_module_of_include(${included} target)
      if(target STREQUAL "" OR target STREQUAL module OR target STREQUAL "tests")
        continue()
      endif()
      if(runtime_index GREATER -1 AND target STREQUAL "anim_authoring")
        list(APPEND found "${source}:${line_number}: #include \"${included}\": ${module}/ is per-frame code and may not include anim_authoring/")
        continue()
      endif()
      arview_layer_of(${target} target_layer)
      if(target_layer STREQUAL "")
        list(APPEND found "${source}:${line_number}: #include \"${included}\": ${target}/ is not in ARVIEW_LAYERS (cmake/ArviewBoundaries.cmake)")
      elseif(NOT target_layer LESS layer)
        list(APPEND found "${source}:${line_number}: #include \"${included}\": ${module}/ (layer ${layer}) may include only modules below it, ${target}/ is layer ${target_layer}")
      endif()
    endforeach()
  endforeach()
  set(${out_list} ${found} PARENT_SCOPE)
endfunction()

# Fails the configure (or the script) with one line per violation, if there are any.
function(arview_fail_on_violations violations)
  if(violations)
    list(JOIN violations "\n  " text)
    message(FATAL_ERROR "architecture boundaries broken (docs/architecture.md, \"Boundaries\"):\n  ${text}")
  endif()
endfunction()

function(arview_check_includes source_dir)
  set(violations "")
  foreach(entry IN LISTS ARVIEW_LAYERS)
    string(REPLACE ":" ";" pair "${entry}")
    list(GET pair 0 module)
    if(NOT IS_DIRECTORY ${source_dir}/${module})
      list(APPEND violations "${module}/: listed in ARVIEW_LAYERS but not in the tree")
      continue()
    endif()
    arview_check_module_includes(${source_dir} ${module} violations)
  endforeach()
  arview_fail_on_violations("${violations}")
endfunction()

# Every arview library a target links, directly or through another library.
function(arview_linked_libraries target out)
  set(seen "")
  set(queue ${target})
  while(queue)
    list(POP_FRONT queue current)
    if(NOT TARGET ${current})
      continue()
    endif()
    get_target_property(aliased ${current} ALIASED_TARGET)
    if(aliased)
      set(current ${aliased})
    endif()
    if(current IN_LIST seen)
      continue()
    endif()
    list(APPEND seen ${current})
    get_target_property(type ${current} TYPE)
    set(links "")
    if(NOT type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(direct ${current} LINK_LIBRARIES)
      if(direct)
        list(APPEND links ${direct})
      endif()
    endif()
    get_target_property(interface ${current} INTERFACE_LINK_LIBRARIES)
    if(interface)
      list(APPEND links ${interface})
    endif()
    foreach(link IN LISTS links)
      if(link MATCHES "^arview")
        list(APPEND queue ${link})
      endif()
    endforeach()
  endwhile()
  list(REMOVE_ITEM seen ${target})
  set(${out} ${seen} PARENT_SCOPE)
endfunction()

function(arview_check_runtime_links)
  set(violations "")
  foreach(module IN LISTS ARVIEW_RUNTIME_MODULES)
    string(REPLACE "app/" "" name ${module})
    arview_linked_libraries(arview_${name} linked)
    if("arview_anim_authoring" IN_LIST linked)
      list(APPEND violations "arview_${name} (${module}/) links arview_anim_authoring: per-frame code may not")
    endif()
  endforeach()
  arview_fail_on_violations("${violations}")
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND CMAKE_SCRIPT_MODE_FILE STREQUAL CMAKE_CURRENT_LIST_FILE)
  if(NOT ARVIEW_SOURCE_DIR)
    message(FATAL_ERROR "usage: cmake -DARVIEW_SOURCE_DIR=<checkout> -P cmake/ArviewBoundaries.cmake")
  endif()
  arview_check_includes(${ARVIEW_SOURCE_DIR})
  message(STATUS "architecture boundaries hold")
endif()
