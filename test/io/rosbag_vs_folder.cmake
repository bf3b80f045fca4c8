# End to end through the programs: the same short sparse simulated sequence written by
# ctlio_simulate as a ctlio folder and as a ROS 1 bag, run by ctlio_odometry with the format
# detected from the path, gives the same trajectory for Singer-LIO and the baseline; the bag run
# logs that the extrinsic came from /tf_static and writes its (fallback) plots.
#
# Tolerance 1e-9 m (measured: 0 m; the odometry does not depend on the heap layout, which the
# bag library changes). The inputs themselves are bit-identical (rosbag_trajectory_test.cc).
# Variables: SIM, ODO (programs), CONFIG (data/sim_lio.yaml), OUT (scratch folder).
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
set(seq --regime=medium --index=2 --duration=0.8 --beams=16 --firing_decimation=8
        --newer_college_extrinsic)
# The folder starts at t = 0 by default, a bag at 1 s: give both the same start.
foreach(layout ctlio rosbag)
  if(layout STREQUAL "ctlio")
    set(target ${OUT}/folder)
  else()
    set(target ${OUT}/run.bag)
  endif()
  execute_process(COMMAND ${SIM} ${seq} --layout=${layout} --output=${target} --start_s=1
                  RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ctlio_simulate --layout=${layout} failed (${rc}):\n${log}")
  endif()
endforeach()
foreach(input folder run.bag)
  # Plots only for the bag run, and there the SVG fallback (--python=false): matplotlib's import
  # alone would take seconds (the PNG path is run by scripts/run_main.sh).
  if(input STREQUAL "folder")
    set(plot --plot=false)
  else()
    set(plot --python=false)
  endif()
  execute_process(COMMAND ${ODO} --dataset=${OUT}/${input} --config=${CONFIG}
                          --method=singer_lio,imu_input --out=${OUT}/out_${input} --progress=false
                          ${plot}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ctlio_odometry on ${input} failed (${rc}):\n${log}")
  endif()
  if(input STREQUAL "run.bag" AND NOT log MATCHES "T_imu_lidar from the bag's /tf_static")
    message(FATAL_ERROR "the bag run did not take the extrinsic from /tf_static:\n${log}")
  endif()
endforeach()
# The SVG top views with their wrapped title and metre axes.
foreach(method singer_lio imu_input)
  file(READ ${OUT}/out_run.bag/${method}/trajectory_topview.svg svg)
  # The title wraps at a width that depends on the scratch path's length: check its words.
  if(NOT svg MATCHES "${method} on" OR NOT svg MATCHES "rosbag:" OR NOT svg MATCHES "ATE" OR
     NOT svg MATCHES "cm</text>" OR NOT svg MATCHES "x \\[m\\]")
    message(FATAL_ERROR "${method}: the SVG top view lacks its title or axes")
  endif()
endforeach()
foreach(method singer_lio imu_input)
  execute_process(
    COMMAND python3 -c "
import sys
a = [l.split() for l in open(sys.argv[1]) if not l.startswith('#')]
b = [l.split() for l in open(sys.argv[2]) if not l.startswith('#')]
assert len(a) == len(b) and len(a) >= 7, 'pose counts %d vs %d' % (len(a), len(b))
worst = max(sum((float(p) - float(q)) ** 2 for p, q in zip(x[1:4], y[1:4])) ** 0.5
            for x, y in zip(a, b))
assert all(x[0] == y[0] for x, y in zip(a, b)), 'pose times differ'
print('max position difference %.3g m over %d poses' % (worst, len(a)))
sys.exit(0 if worst < 1e-9 else 1)
" ${OUT}/out_folder/${method}/trajectory.tum ${OUT}/out_run.bag/${method}/trajectory.tum
    RESULT_VARIABLE rc OUTPUT_VARIABLE log ERROR_VARIABLE log)
  message(STATUS "${method}: ${log}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${method}: folder and bag trajectories differ: ${log}")
  endif()
endforeach()
