# ctlio_odometry with a perturbed nominal extrinsic (--sim_extrinsic_error), with and without
# online calibration (used by lio.Odometry.SimExtrinsicError): evaluation.txt reports the
# starting error as given, and the final one — unchanged without calibration, with its σ and
# 3σ coverage with it. Tiny size (1 s, 16 beams, every 8th firing): a check of the plumbing,
# not of the accuracy (test/lio/extrinsic_calibration_test.cc, README "Online calibration").
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
file(READ ${SOURCE_DIR}/data/sim_lio.yaml base)
file(WRITE ${OUT}/calibration.yaml "${base}\ncalibration:\n  estimate_extrinsic: true\n")
foreach(mode fixed calibrated)
  set(config ${SOURCE_DIR}/data/sim_lio.yaml)
  if(mode STREQUAL "calibrated")
    set(config ${OUT}/calibration.yaml)
  endif()
  execute_process(
    COMMAND ${EXE} --format sim --sim_regime medium --sim_index 100 --sim_duration 1
            --sim_beams 16 --sim_firing_decimation 8 --sim_extrinsic_error=3deg,0.10m
            --config ${config} --method singer_lio --out ${OUT}/${mode}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ctlio_odometry (${mode}) failed (${rc}):\n${out}\n${err}")
  endif()
  file(READ ${OUT}/${mode}/evaluation.txt ev)
  set(expected "extrinsic_initial_error_deg 3\n" "extrinsic_initial_error_cm 10\n")
  if(mode STREQUAL "fixed")
    list(APPEND expected "extrinsic_estimated 0\n" "extrinsic_error_deg 3\n"
         "extrinsic_error_cm 10\n")
  else()
    list(APPEND expected "extrinsic_estimated 1\n" "extrinsic_sigma_deg "
         "extrinsic_rotation_within_3sigma ")
  endif()
  foreach(line ${expected})
    string(FIND "${ev}" "${line}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "${mode}: evaluation.txt lacks '${line}':\n${ev}")
    endif()
  endforeach()
endforeach()
