# Installs the project into a scratch prefix and runs the installed elevation-mapper and
# terrain-sim with --help: they must load the installed library through their RUNPATH, with no
# LD_LIBRARY_PATH. Arguments: -DBUILD_DIR=... -DWORK_DIR=... -DBINDIR=bin
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${rc}):\n${out}\n${err}")
endif()
foreach(program elevation-mapper terrain-sim)
  set(exe ${WORK_DIR}/prefix/${BINDIR}/${program})
  execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH ${exe} --help
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "Usage")
    message(FATAL_ERROR "installed ${exe} --help failed (${rc}):\n${out}\n${err}")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})
