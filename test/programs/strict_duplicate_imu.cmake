cmake_minimum_required(VERSION 3.25)
# ctlio_odometry --strict (issue 40): a ctlio folder whose imu.csv repeats one line is recovered
# without it (the duplicate dropped, exit 0, reported in evaluation.txt and the summary) and
# refused with it (exit non-zero, the defect and the
# file named).
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${SIMULATE} --output=${WORK}/s --regime=medium --duration=1.5 --beams=16
                        --firing_decimation=4
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_simulate: exit ${rc}\n${out}\n${err}")
endif()
# Repeat line 101 of imu.csv (a sample in the middle of the stream): line 102 is the duplicate.
file(STRINGS ${WORK}/s/imu.csv lines)
list(GET lines 100 line)
list(INSERT lines 100 "${line}")
list(JOIN lines "\n" text)
file(WRITE ${WORK}/s/imu.csv "${text}\n")
set(run ${ODOMETRY} --dataset=${WORK}/s --method=singer_lio --progress=false --plot=false
        --config=${SOURCE_DIR}/data/sim_lio.yaml)
execute_process(COMMAND ${run} --out=${WORK}/lenient RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err TIMEOUT 300)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "without --strict: exit ${rc} (expected 0)\n${out}\n${err}")
endif()
string(FIND "${err}" "duplicate IMU time" at)
if(at EQUAL -1)
  message(FATAL_ERROR "without --strict the duplicate is not logged:\n${err}")
endif()
# The recovery is in the run's outputs too, not only in the log (DataSource::InputDefects).
file(READ ${WORK}/lenient/evaluation.txt ev)
string(FIND "${ev}" "input_defect \"duplicate IMU time\" 1 \"${WORK}/s/imu.csv:102\"" at)
if(at EQUAL -1)
  message(FATAL_ERROR "evaluation.txt does not report the recovered duplicate:\n${ev}")
endif()
string(FIND "${out}" "WARNING input: 1 x duplicate IMU time" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the summary does not report the recovered duplicate:\n${out}")
endif()
execute_process(COMMAND ${run} --strict --out=${WORK}/strict RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err TIMEOUT 300)
if(rc EQUAL 0)
  message(FATAL_ERROR "--strict: exit 0 on a duplicated IMU line\n${out}\n${err}")
endif()
foreach(text "imu.csv:102: duplicate IMU time" "--strict")
  string(FIND "${out}${err}" "${text}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "--strict: the error lacks '${text}':\n${out}\n${err}")
  endif()
endforeach()
