cmake_minimum_required(VERSION 3.25)
# A Livox Mid-360 bag (livox_ros_driver2 CustomMsg, IMU in g) runs with only
# --config data/sensors/mid360.yaml: the config's input.accel_scale scales the accelerometer to
# m/s² (no --imu_accel_scale flag), the run tracks; --imu_accel_scale=1 given explicitly wins
# over the config (the reader then warns that the IMU reports g).
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${SIMULATE} --output=${WORK}/mid360.bag --sensor=mid360 --layout=rosbag
                        --regime=walking --world=park --index=100 --duration=3
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_simulate: exit ${rc}\n${out}\n${err}")
endif()
set(run ${ODOMETRY} --dataset=${WORK}/mid360.bag --method=singer_lio --progress=false --plot=false
        --config=${SOURCE_DIR}/data/sensors/mid360.yaml)
execute_process(COMMAND ${run} --out=${WORK}/config RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err TIMEOUT 300)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "with the config only: exit ${rc}\n${out}\n${err}")
endif()
string(FIND "${err}" "seems to report g" at)
if(NOT at EQUAL -1)
  message(FATAL_ERROR "with the config the accelerometer is still in g:\n${err}")
endif()
file(STRINGS ${WORK}/config/evaluation.txt ate REGEX "^ate_rmse_m ")
if(NOT ate MATCHES "^ate_rmse_m ([0-9.eE+-]+)")
  message(FATAL_ERROR "no ate_rmse_m in evaluation.txt:\n${out}")
endif()
set(ate_m ${CMAKE_MATCH_1})
if(NOT ate_m LESS 0.05)
  message(FATAL_ERROR "ATE ${ate_m} m on 3 s of a Mid-360 bag (expected < 5 cm)\n${out}")
endif()
message(STATUS "ATE ${ate_m} m")
# The flag, given explicitly, wins: with --imu_accel_scale=1 the reader keeps g and says so.
execute_process(COMMAND ${run} --imu_accel_scale=1 --max_scans=15 --out=${WORK}/flag
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
string(FIND "${err}" "seems to report g" at)
if(at EQUAL -1)
  message(FATAL_ERROR "--imu_accel_scale=1 did not win over input.accel_scale:\n${out}\n${err}")
endif()
