# End to end through the programs, ROS 2: the short sparse simulated sequence of
# rosbag_vs_folder.cmake written by ctlio_simulate as a ctlio folder, a ROS 2 MCAP bag (zstd
# chunks) and a ROS 2 SQLite bag, run by ctlio_odometry with the format detected from the path
# (Singer-LIO), gives the same trajectory to 1e-9 m; the bag runs take the extrinsic from
# /tf_static, and --write_bag writes the estimate as a ROS 2 bag folder.
# Variables: SIM, ODO (programs), CONFIG (data/sim_lio.yaml), OUT (scratch folder).
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
set(seq --regime=medium --index=2 --duration=0.8 --beams=16 --firing_decimation=8
        --newer_college_extrinsic --start_s=1)
foreach(layout ctlio ros2 ros2_sqlite3)
  set(extra)
  if(layout STREQUAL "ros2")
    set(extra --bag_compression=zstd)
  endif()
  execute_process(COMMAND ${SIM} ${seq} --layout=${layout} --output=${OUT}/${layout} ${extra}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ctlio_simulate --layout=${layout} failed (${rc}):\n${log}")
  endif()
endforeach()
if(NOT EXISTS ${OUT}/ros2/metadata.yaml OR NOT EXISTS ${OUT}/ros2_ground_truth.tum)
  message(FATAL_ERROR "--layout=ros2 wrote no bag folder with metadata.yaml and ground truth")
endif()
foreach(input ctlio ros2 ros2_sqlite3)
  execute_process(COMMAND ${ODO} --dataset=${OUT}/${input} --config=${CONFIG} --method=singer_lio
                          --out=${OUT}/out_${input} --progress=false --plot=false --write_bag
                  RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ctlio_odometry on ${input} failed (${rc}):\n${log}")
  endif()
  if(NOT input STREQUAL "ctlio")
    if(NOT log MATCHES "T_imu_lidar from the bag's /tf_static")
      message(FATAL_ERROR "the ${input} run did not take the extrinsic from /tf_static:\n${log}")
    endif()
    if(NOT EXISTS ${OUT}/out_${input}/trajectory_bag/metadata.yaml)
      message(FATAL_ERROR "--write_bag on a ROS 2 bag wrote no ROS 2 bag folder trajectory_bag")
    endif()
  endif()
  if(NOT input STREQUAL "ctlio")
    execute_process(
      COMMAND python3 -c "
import sys
a = [l.split() for l in open(sys.argv[1]) if not l.startswith('#')]
b = [l.split() for l in open(sys.argv[2]) if not l.startswith('#')]
assert len(a) == len(b) and len(a) >= 7, 'pose counts %d vs %d' % (len(a), len(b))
assert all(x[0] == y[0] for x, y in zip(a, b)), 'pose times differ'
worst = max(sum((float(p) - float(q)) ** 2 for p, q in zip(x[1:4], y[1:4])) ** 0.5
            for x, y in zip(a, b))
print('max position difference %.3g m over %d poses' % (worst, len(a)))
sys.exit(0 if worst < 1e-9 else 1)
" ${OUT}/out_ctlio/trajectory.tum ${OUT}/out_${input}/trajectory.tum
      RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
    message(STATUS "${input}: ${log}")
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${input}: folder and ROS 2 bag trajectories differ: ${log}")
    endif()
  endif()
endforeach()
