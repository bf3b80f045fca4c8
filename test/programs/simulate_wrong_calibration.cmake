cmake_minimum_required(VERSION 3.25)
# ctlio_simulate --extrinsic_error and --imu_stamp_offset in every layout (issue 45): a bag carries
# the nominal extrinsic on /tf_static (3° off the truth) and writes the truth beside it as a config
# overlay (<stem>_true_calibration.yaml), which ctlio_odometry composes after its config; the
# Newer College layout (read with the published extrinsic) gets a truth 3° / 10 cm off it.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
# A command that must run (exit 0; the odometry's exit 1, a tiny run with no ATE, is accepted: only
# the extrinsic it read is checked).
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  TIMEOUT 120)
  if(NOT rc MATCHES "^[01]$" OR (rc EQUAL 1 AND NOT "${ARGV0}" STREQUAL "${ODOMETRY}"))
    message(FATAL_ERROR "exit ${rc}: ${ARGN}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
  set(err "${err}" PARENT_SCOPE)
endfunction()
function(expect text haystack what)
  string(FIND "${haystack}" "${text}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${what} lacks '${text}':\n${haystack}")
  endif()
endfunction()
set(wrong --extrinsic_error=3deg,0.10m --imu_stamp_offset=0.02 --duration=1 --beams=8
          --firing_decimation=60)
run(${SIMULATE} --layout=rosbag --output=${WORK}/s.bag ${wrong})
file(READ ${WORK}/s_true_calibration.yaml truth)
expect("calibration:\n  time_offset_s: [0.02]\nextrinsic:\n  rotation: [" "${truth}"
       "s_true_calibration.yaml")
set(tiny --dataset=${WORK}/s.bag --method=lidar_only --progress=false --plot=false --max_scans=3)
run(${ODOMETRY} ${tiny} --config=${SOURCE_DIR}/data/sim_lio.yaml --out=${WORK}/nominal)
expect("T_imu_lidar from the bag's /tf_static" "${err}" "the bag run's log")
expect("rotation 3 deg" "${err}" "the bag run's log")
run(${ODOMETRY} ${tiny} --config=${SOURCE_DIR}/data/sim_lio.yaml,${WORK}/s_true_calibration.yaml
    --out=${WORK}/true)
expect("T_imu_lidar from the config (extrinsic:): translation [0 0 0] m, rotation 0 deg" "${err}"
       "the run with the truth overlay")
run(${SIMULATE} --layout=newer_college --preset=newer_college --output=${WORK}/nc ${wrong})
file(READ ${WORK}/nc/true_calibration.yaml truth)
expect("time_offset_s: [0.02]" "${truth}" "nc/true_calibration.yaml")
