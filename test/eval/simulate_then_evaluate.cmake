# ctest driver: ctlio_simulate → ctlio_evaluate on the simulator's own ground truth.
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${SIMULATE} --regime=medium --index=2 --duration=1 --beams=8
                        --firing_decimation=50 --output=${WORK_DIR}/seq
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_simulate failed (${rc}): ${err}")
endif()
if(NOT err MATCHES "scan 10/10")
  message(FATAL_ERROR "ctlio_simulate showed no progress: ${err}")
endif()
foreach(f ctlio_sim.yaml imu.csv scans.csv scans/000009.bin ground_truth.csv ground_truth_tum.txt)
  if(NOT EXISTS ${WORK_DIR}/seq/${f})
    message(FATAL_ERROR "ctlio_simulate did not write ${f}")
  endif()
endforeach()
execute_process(COMMAND ${EVALUATE} --estimate=${WORK_DIR}/seq/ground_truth_tum.txt
                        --reference=${WORK_DIR}/seq/ground_truth_tum.txt --align=sim3
                        --rpe_distances=0.05 --rpe_times=0.2 --output_dir=${WORK_DIR}/eval
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_evaluate failed (${rc}): ${out} ${err}")
endif()
if(NOT out MATCHES "ATE \\[m\\] +rmse 0\\.000000")
  message(FATAL_ERROR "ATE of a trajectory against itself is not 0: ${out}")
endif()
foreach(f metrics.txt metrics.json errors.csv)
  if(NOT EXISTS ${WORK_DIR}/eval/${f})
    message(FATAL_ERROR "ctlio_evaluate did not write ${f}")
  endif()
endforeach()
# Plots are optional (python3-matplotlib); the program must say what it did either way.
if(NOT out MATCHES "(wrote top_view.png|plots skipped)")
  message(FATAL_ERROR "ctlio_evaluate said nothing about plots: ${out}")
endif()
# Bad input: a clear error naming the file, non-zero exit.
execute_process(COMMAND ${EVALUATE} --estimate=${WORK_DIR}/missing.txt
                        --reference=${WORK_DIR}/seq/ground_truth_tum.txt
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "missing.txt: file not found")
  message(FATAL_ERROR "missing estimate not reported: ${err}")
endif()
