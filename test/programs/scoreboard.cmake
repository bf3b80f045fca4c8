# ctlio_scoreboard over real ctlio_experiment cell folders (issue 42): one tiny cell (VLP-16 model,
# box, fast, 1 sequence × 0.6 s, both methods) and one unfinished cell (a CELL.tmp without
# results.csv, as an interrupted scripts/scoreboard.sh leaves it). The table must hold the one
# finished cell, labelled by the settings' sensor and world, say REDUCED, and name the skipped one;
# a folder that is no cell must be an error naming it.
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${EXPERIMENT} --out ${OUT}/cells/vlp16_box_fast --sim_sensor vlp16
                        --world box --regimes fast --methods singer_lio,imu_input --sequences 1
                        --duration 0.6 --threads 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the cell's experiment failed (${rc}):\n${out}\n${err}")
endif()
file(MAKE_DIRECTORY ${OUT}/cells/os1_64_box_fast.tmp)
execute_process(COMMAND ${BOARD} --cells_under ${OUT}/cells --out ${OUT}/board
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_scoreboard failed (${rc}):\n${out}\n${err}")
endif()
if(NOT err MATCHES "skipped .*os1_64_box_fast.tmp \\(no results.csv: unfinished\\)")
  message(FATAL_ERROR "the unfinished cell was not named as skipped:\n${err}")
endif()
file(STRINGS ${OUT}/board/scoreboard.csv lines)
list(LENGTH lines n)
list(GET lines 1 row)
if(NOT n EQUAL 2 OR NOT row MATCHES "^vlp16,box,fast,1,")
  message(FATAL_ERROR "expected one cell vlp16,box,fast with 1 run, got ${n} lines:\n${lines}")
endif()
file(READ ${OUT}/board/scoreboard.md md)
if(NOT md MATCHES "\\*\\*REDUCED\\*\\*" OR NOT md MATCHES "\\| vlp16 \\| box \\| fast \\| 1 \\|")
  message(FATAL_ERROR "the table lacks the REDUCED header or the cell:\n${md}")
endif()
execute_process(COMMAND ${BOARD} --cells ${OUT}/cells/os1_64_box_fast.tmp --out ${OUT}/bad
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "os1_64_box_fast.tmp/settings.txt: cannot open")
  message(FATAL_ERROR "a folder that is no cell was not refused by name (${rc}):\n${err}")
endif()
