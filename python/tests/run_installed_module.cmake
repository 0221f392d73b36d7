# Installs the project into a scratch prefix and imports the installed Python module with only
# that prefix's module folder on PYTHONPATH and no LD_LIBRARY_PATH (its RUNPATH finds the
# library); checks that the folder under /usr/local is on the interpreter's own sys.path.
# Arguments: -DBUILD_DIR=... -DWORK_DIR=... -DPYTHON=/usr/bin/python3 -DMODULE_DIR=lib/python3.11/...
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${rc}):\n${out}\n${err}")
endif()
set(code "import sys, multibin; m = multibin.ElevationMap(resolution_m=0.05); \
print(multibin.__file__); print('/usr/local/${MODULE_DIR}' in sys.path)")
execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH
                        PYTHONPATH=${WORK_DIR}/prefix/${MODULE_DIR} ${PYTHON} -c "${code}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT out MATCHES "${WORK_DIR}/prefix/${MODULE_DIR}/multibin")
  message(FATAL_ERROR "the installed module did not import (${rc}):\n${out}\n${err}")
endif()
if(NOT out MATCHES "True")
  message(FATAL_ERROR "/usr/local/${MODULE_DIR} is not on ${PYTHON}'s sys.path:\n${out}")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
