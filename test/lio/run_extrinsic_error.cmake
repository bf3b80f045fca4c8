# ctlio_odometry with a perturbed nominal extrinsic (--sim_extrinsic_error), with and without
# online calibration (used by lio.Odometry.SimExtrinsicError): evaluation.txt reports the
# starting error as given, and the final one — unchanged without calibration, with its σ and
# 3σ coverage with it. Tiny size (1 s, 16 beams, every 8th firing): a check of the plumbing,
# not of the accuracy (test/lio/extrinsic_calibration_test.cc, docs/experiments/calibration.md).
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
file(READ ${SOURCE_DIR}/data/sim_lio.yaml shipped)
# The reduced sensor's subsampling (data/sim_lio.yaml's comment: 0.5 m below full resolution).
string(REGEX REPLACE "\n  voxel_size: [0-9.]+\n" "\n  voxel_size: 0.5\n" base "${shipped}")
string(REGEX REPLACE "\n  initial_voxel_size: [0-9.]+\n" "\n  initial_voxel_size: 0.5\n" base
                     "${base}")
string(FIND "${base}" "\n  voxel_size: 0.5\n" at_size)
string(FIND "${base}" "\n  initial_voxel_size: 0.5\n" at_initial)
if(at_size LESS 0 OR at_initial LESS 0)
  message(FATAL_ERROR "data/sim_lio.yaml: no lidar_frontend voxel_size / initial_voxel_size to set")
endif()
file(WRITE ${OUT}/reduced.yaml "${base}")
# The calibrated run composes its config on the command line: reduced.yaml, then an overlay.
file(WRITE ${OUT}/estimate_extrinsic.yaml "calibration:\n  estimate_extrinsic: true\n")

# Singer-LIO on the tiny sequence with the 3° / 10 cm nominal extrinsic, config `config`, into
# ${OUT}/${mode}; a failure stops the test with the program's output.
function(run_odometry mode config)
  execute_process(
    COMMAND ${EXE} --format sim --sim_regime medium --sim_index 100 --sim_duration 1
            --sim_beams 16 --sim_firing_decimation 8 --sim_extrinsic_error=3deg,0.10m
            --config ${config} --method singer_lio --out ${OUT}/${mode}
            # The replay on its thread, adopted with the scan that reaches the span (as inside
            # it): calibration_live.csv then ends there (the default adopts at the end of this
            # 1 s input, every scan live; lio.BackgroundReplay.* tests the equivalence).
            --warmup_replay_adopt_after_s=0
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ctlio_odometry (${mode}) failed (${rc}):\n${out}\n${err}")
  endif()
  file(WRITE ${OUT}/${mode}.stdout "${out}")
endfunction()

foreach(mode fixed calibrated)
  set(config ${OUT}/reduced.yaml)
  if(mode STREQUAL "calibrated")
    set(config ${OUT}/reduced.yaml,${OUT}/estimate_extrinsic.yaml)
  endif()
  run_odometry(${mode} ${config})
  if(mode STREQUAL "calibrated")  # the run names every file of its config
    file(READ ${OUT}/${mode}.stdout printed)
    string(FIND "${printed}"
           "config: ${OUT}/reduced.yaml, ${OUT}/estimate_extrinsic.yaml; later files win" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "the config line does not list both files:\n${printed}")
    endif()
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
  # With calibration: the per-scan log has the extrinsic's columns and calibration.yaml a
  # pasteable extrinsic: section and a block per coordinate with the truth (which the plot
  # reads); without, neither.
  if(mode STREQUAL "calibrated")
    file(STRINGS ${OUT}/${mode}/calibration.csv rows)
    list(GET rows 0 header)
    foreach(column extrinsic_rho_x_m extrinsic_rho_x_sigma_m extrinsic_phi_z_deg
                   extrinsic_phi_z_sigma_deg)
      string(FIND "${header}" "${column}" at)
      if(at EQUAL -1)
        message(FATAL_ERROR "calibration.csv header lacks ${column}: ${header}")
      endif()
    endforeach()
    list(LENGTH rows n)
    if(n LESS 3)
      message(FATAL_ERROR "calibration.csv has ${n} lines, expected one per scan")
    endif()
    file(READ ${OUT}/${mode}/calibration.yaml yaml)
    foreach(text "\nextrinsic:\n  rotation: [" "\n  translation: [" "\n# extrinsic_rho_x [cm]\n"
                 "\n#   truth      ")
      string(FIND "${yaml}" "${text}" at)
      if(at EQUAL -1)
        message(FATAL_ERROR "calibration.yaml lacks '${text}':\n${yaml}")
      endif()
    endforeach()
    if(EXISTS ${OUT}/${mode}/calibration_live.csv)
      message(FATAL_ERROR "calibration_live.csv written without a warm-up replay")
    endif()
  elseif(EXISTS ${OUT}/${mode}/calibration.csv)
    message(FATAL_ERROR "calibration.csv written without calibration")
  endif()
endforeach()

# The written calibration.yaml is an overlay: after reduced.yaml it gives the run its extrinsic
# (here the start wherever sigma kept it), with no estimation.
run_odometry(pasted ${OUT}/reduced.yaml,${OUT}/calibrated/calibration.yaml)
file(READ ${OUT}/pasted/evaluation.txt ev)
string(FIND "${ev}" "extrinsic_estimated 0\n" at)
if(at EQUAL -1)
  message(FATAL_ERROR "pasted: evaluation.txt lacks 'extrinsic_estimated 0':\n${ev}")
endif()

# With a warm-up replay (calibration.warmup_replay_s, 0.5 s here): calibration.csv holds the
# replayed estimates of every scan, calibration_live.csv the ones returned live up to the replay
# (same columns, fewer rows), which the plot draws beside them; evaluation.txt says how many
# scans the replay revised.
file(WRITE ${OUT}/replay.yaml
     "${base}\ncalibration:\n  estimate_extrinsic: true\n  warmup_replay_s: 0.5\n")
run_odometry(replayed ${OUT}/replay.yaml)
# The lines of ${mode}'s calibration.csv and calibration_live.csv into `rows` and `live`, whose
# headers must be the same.
function(read_calibration_logs mode)
  file(STRINGS ${OUT}/${mode}/calibration.csv r)
  file(STRINGS ${OUT}/${mode}/calibration_live.csv l)
  list(GET r 0 header)
  list(GET l 0 live_header)
  if(NOT header STREQUAL live_header)
    message(FATAL_ERROR "${mode}: calibration_live.csv header differs:\n${live_header}\n${header}")
  endif()
  set(rows "${r}" PARENT_SCOPE)
  set(live "${l}" PARENT_SCOPE)
endfunction()
read_calibration_logs(replayed)
list(LENGTH rows n)
list(LENGTH live n_live)
if(n_live LESS 3 OR NOT n_live LESS n)
  message(FATAL_ERROR "calibration_live.csv has ${n_live} lines, calibration.csv ${n}: expected "
                      "the scans up to the replay only")
endif()
file(READ ${OUT}/replayed/evaluation.txt ev)
string(REGEX MATCH "warmup_replayed_scans ([0-9]+)" m "${ev}")
if(NOT m OR CMAKE_MATCH_1 EQUAL 0)
  message(FATAL_ERROR "evaluation.txt does not report the replay:\n${ev}")
endif()

# A held last pass (calibration.warmup_replay_passes 2, warmup_replay_hold): calibration.csv and
# calibration_live.csv gain a <coordinate>_held column each (the same header in both), 1 in the
# replayed scans of the span, 0 after it and in every live scan; the plot draws those spans.
file(WRITE ${OUT}/held.yaml
     "${base}\ncalibration:\n  estimate_extrinsic: true\n  warmup_replay_s: 0.5\n"
     "  warmup_replay_passes: 2\n  warmup_replay_hold: true\n")
run_odometry(held ${OUT}/held.yaml)
# Column `name` of a CSV file's rows (header first) into `out`, the header excluded.
function(csv_column file name out)
  file(STRINGS ${file} lines)
  list(GET lines 0 header)
  string(REPLACE "," ";" header "${header}")
  list(FIND header ${name} at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${file} lacks the column ${name}: ${header}")
  endif()
  list(REMOVE_AT lines 0)
  set(values "")
  foreach(line ${lines})
    string(REPLACE "," ";" fields "${line}")
    list(GET fields ${at} v)
    list(APPEND values ${v})
  endforeach()
  set(${out} "${values}" PARENT_SCOPE)
endfunction()
read_calibration_logs(held)
csv_column(${OUT}/held/calibration.csv t_s times)
foreach(coordinate extrinsic_rho_x extrinsic_phi_z)
  csv_column(${OUT}/held/calibration.csv ${coordinate}_held held)
  csv_column(${OUT}/held/calibration_live.csv ${coordinate}_held held_live)
  list(FIND held_live 1 live_one)
  if(NOT live_one EQUAL -1)
    message(FATAL_ERROR "held: a live scan reports ${coordinate} held: ${held_live}")
  endif()
  list(LENGTH times n)
  math(EXPR last "${n} - 1")
  set(in_span 0)
  set(after_span 0)
  foreach(i RANGE 1 ${last})  # the initialising scan has no solve
    list(GET times ${i} t)
    list(GET held ${i} h)
    if(t LESS 0.5)
      if(NOT h EQUAL 1)
        message(FATAL_ERROR "held: ${coordinate} not held at t = ${t} s in the span: ${held}")
      endif()
      math(EXPR in_span "${in_span} + 1")
    elseif(t GREATER 0.65)
      if(NOT h EQUAL 0)
        message(FATAL_ERROR "held: ${coordinate} still held at t = ${t} s: ${held}")
      endif()
      math(EXPR after_span "${after_span} + 1")
    endif()
  endforeach()
  if(in_span LESS 3 OR after_span LESS 2)
    message(FATAL_ERROR "held: ${in_span} scans in the span, ${after_span} after it: ${times}")
  endif()
endforeach()
execute_process(COMMAND python3 -c "import matplotlib" RESULT_VARIABLE no_matplotlib
                OUTPUT_QUIET ERROR_QUIET)
if(no_matplotlib EQUAL 0 AND NOT EXISTS ${OUT}/held/calibration.png)
  message(FATAL_ERROR "held: no calibration.png although python3 has matplotlib")
endif()
