# Projects that use ctlio through find_package(ctlio), as a user's would.
#   -DMODE=install: installs the built ctlio (CTLIO_BINARY_DIR) into ${WORK_DIR}/prefix, once for
#                   every such project (the ctest fixture ctlio_installed).
#   -DMODE=run:     configures and builds the project in SOURCE_DIR against that prefix
#                   (build folder ${WORK_DIR}/build-${NAME}), then runs its program PROGRAM with
#                   the argument ${WORK_DIR}/run-${NAME} (a fresh folder for its files).
set(prefix ${WORK_DIR}/prefix)
if(MODE STREQUAL "install")
  file(REMOVE_RECURSE ${prefix})
  execute_process(COMMAND ${CMAKE_COMMAND} --install ${CTLIO_BINARY_DIR} --prefix ${prefix}
                  RESULT_VARIABLE rc OUTPUT_QUIET)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "cmake --install failed (${rc})")
  endif()
  return()
endif()
if(NOT MODE STREQUAL "run")
  message(FATAL_ERROR "run_consumer.cmake: MODE must be install or run, got '${MODE}'")
endif()
set(build ${WORK_DIR}/build-${NAME})
set(run ${WORK_DIR}/run-${NAME})
file(REMOVE_RECURSE ${build} ${run})
file(MAKE_DIRECTORY ${run})
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${build}
                        -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release
                        -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
                        -DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_COMPILER_LAUNCHER}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring ${SOURCE_DIR} against the installed ctlio failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${build} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "building ${SOURCE_DIR} against the installed ctlio failed")
endif()
execute_process(COMMAND ${build}/${PROGRAM} ${run} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PROGRAM} failed (${rc})")
endif()
