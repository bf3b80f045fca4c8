# Runs ctlio_experiment at a tiny size and checks its outputs (used by lio.Experiment.TinyTable2).
file(REMOVE_RECURSE ${OUT})
execute_process(
  COMMAND ${EXE} --out ${OUT} --sequences 1 --duration 0.6 --beams 16 --firing_decimation 8
          --threads 1 --methods singer_lio,imu_input
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_experiment failed (${rc}):\n${out}\n${err}")
endif()
foreach(f table.md results.csv table2.svg)
  if(NOT EXISTS ${OUT}/${f})
    message(FATAL_ERROR "ctlio_experiment did not write ${OUT}/${f}")
  endif()
endforeach()
file(READ ${OUT}/table.md table)
foreach(row "| slow | singer_lio |" "| medium | imu_input |" "| fast | singer_lio |" "REDUCED")
  string(FIND "${table}" "${row}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "table.md lacks '${row}':\n${table}")
  endif()
endforeach()
file(STRINGS ${OUT}/results.csv lines)
list(LENGTH lines n)
if(NOT n EQUAL 7)  # header + 3 regimes × 2 methods
  message(FATAL_ERROR "results.csv has ${n} lines, expected 7")
endif()
