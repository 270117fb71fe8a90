# ctest `architecture.boundaries_catch_planted`: the boundary check (cmake/ArviewBoundaries.cmake)
# run on a copy of the tree with two violations planted must fail and name both:
#   render/planted.cpp         per-frame code including anim_authoring/
#   app/pipeline/planted.cpp   a module including one above it (app/session/)
# Run as: cmake -DARVIEW_SOURCE_DIR=<checkout> -DWORK_DIR=<scratch> -P planted_violations.cmake
include(${ARVIEW_SOURCE_DIR}/cmake/ArviewBoundaries.cmake)

file(REMOVE_RECURSE ${WORK_DIR})
foreach(entry IN LISTS ARVIEW_LAYERS)
  string(REPLACE ":" ";" pair "${entry}")
  list(GET pair 0 module)
  file(GLOB sources ${ARVIEW_SOURCE_DIR}/${module}/*.h ${ARVIEW_SOURCE_DIR}/${module}/*.cpp)
  file(COPY ${sources} DESTINATION ${WORK_DIR}/${module})
endforeach()
file(WRITE ${WORK_DIR}/render/planted.cpp "#include \"render/ar_renderer.h\"\n#include \"anim_authoring/scene.h\"\n")
file(WRITE ${WORK_DIR}/app/pipeline/planted.cpp "// planted\n#include \"app/session/ar_session.h\"\n")

execute_process(COMMAND ${CMAKE_COMMAND} -DARVIEW_SOURCE_DIR=${WORK_DIR} -P ${ARVIEW_SOURCE_DIR}/cmake/ArviewBoundaries.cmake
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(report "${out}${err}")
if(status EQUAL 0)
  message(FATAL_ERROR "the boundary check passed a tree with two planted violations:\n${report}")
endif()
foreach(expected
    "render/planted.cpp:2: #include \"anim_authoring/scene.h\": render/ is per-frame code"
    "app/pipeline/planted.cpp:2: #include \"app/session/ar_session.h\": app/pipeline/ (layer 5) may include only modules below it")
  string(FIND "${report}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the boundary check's report lacks \"${expected}\":\n${report}")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})
message(STATUS "both planted violations were caught")
