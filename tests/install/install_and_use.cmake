# cmake -DBUILD_DIR=<grbd build> -DWORK_DIR=<scratch> -DGENERATOR=<generator> -P install_and_use.cmake
#
# grbd as another project uses it: install the build into a prefix of its own, configure and
# build the small project in consumer/ against it with find_package(grbd), run its program.
# Fails, saying which step, when any of them does.
file(REMOVE_RECURSE ${WORK_DIR})
function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("${what}: exit code ${result}\n${out}${err}")
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "install test: ${what} failed")
  endif()
endfunction()
step("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
# The package carries what using the library needs and none of the project's own warning flags.
file(GLOB_RECURSE _targets ${WORK_DIR}/prefix/*/grbdTargets.cmake)
if(NOT _targets)
  message(FATAL_ERROR "install test: no grbdTargets.cmake under ${WORK_DIR}/prefix")
endif()
file(READ "${_targets}" _exported)
if(_exported MATCHES "-W(all|error|extra|pedantic)|grbd_flags|/lib/include")
  message(FATAL_ERROR "install test: the exported target carries the project's build settings "
                      "('${CMAKE_MATCH_0}' in ${_targets})")
endif()
step("configure the user's project" ${CMAKE_COMMAND} -S ${CMAKE_CURRENT_LIST_DIR}/consumer
     -B ${WORK_DIR}/build -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release
     -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
step("build it" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
step("run it" ${WORK_DIR}/build/two_spheres)
file(REMOVE_RECURSE ${WORK_DIR})
