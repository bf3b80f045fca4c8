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
# The bars' labels (RMSE ATE in cm) carry two significant digits: one decimal showed 0.26 and
# 0.34 cm both as "0.3".
file(READ ${OUT}/table2.svg svg)
string(REGEX MATCHALL "font-size='10'>[^<]*<" labels "${svg}")
list(LENGTH labels n)
if(NOT n EQUAL 6)  # 3 regimes × 2 methods
  message(FATAL_ERROR "table2.svg has ${n} bar labels, expected 6:\n${svg}")
endif()
foreach(label ${labels})
  string(REGEX REPLACE "font-size='10'>([^<]*)<" "\\1" value "${label}")
  string(REGEX REPLACE "e.*$" "" mantissa "${value}")
  string(REGEX REPLACE "[.]" "" digits "${mantissa}")
  string(REGEX REPLACE "^0+" "" digits "${digits}")
  string(LENGTH "${digits}" length)
  if(length LESS 1 OR length GREATER 2)
    message(FATAL_ERROR "table2.svg bar label '${value}' is not two significant digits")
  endif()
endforeach()
