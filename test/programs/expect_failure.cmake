cmake_minimum_required(VERSION 3.25)
# Runs COMMAND (a ;-list, "<WORK>" replaced by a fresh scratch folder WORK) and passes if it exits
# non-zero with EXPECT in its output. Two set-up switches, removed from the command:
#   --link_trajectory_to_dev_full   WORK/out/trajectory.tum is a symlink to /dev/full (ENOSPC);
#   --evaluation_is_a_directory     WORK/out/evaluation.txt is a directory.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/out)
string(REPLACE "<WORK>" "${WORK}" COMMAND "${COMMAND}")
if("--link_trajectory_to_dev_full" IN_LIST COMMAND)
  list(REMOVE_ITEM COMMAND "--link_trajectory_to_dev_full")
  file(CREATE_LINK /dev/full ${WORK}/out/trajectory.tum SYMBOLIC)
endif()
if("--evaluation_is_a_directory" IN_LIST COMMAND)
  list(REMOVE_ITEM COMMAND "--evaluation_is_a_directory")
  file(MAKE_DIRECTORY ${WORK}/out/evaluation.txt)
endif()
execute_process(COMMAND ${COMMAND} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                TIMEOUT 120)
if(rc EQUAL 0)
  message(FATAL_ERROR "exit 0 (expected a failure mentioning '${EXPECT}'):\n${out}\n${err}")
endif()
if(NOT rc MATCHES "^[0-9]+$")
  message(FATAL_ERROR "did not exit normally (${rc}):\n${out}\n${err}")
endif()
string(FIND "${out}${err}" "${EXPECT}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "exit ${rc} without '${EXPECT}' in the output:\n${out}\n${err}")
endif()
