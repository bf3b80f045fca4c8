# ctlio_geometry_report on a folder the readers open (a short simulated sequence in the office),
# the same sweep as ctlio_simulate --geometry_report prints, and bad input named.
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${SIMULATE} --world office --regime walking --duration 0.3 --beams 32
                        --firing_decimation 4 --output ${OUT}/office
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_simulate failed (${rc}):\n${err}")
endif()
execute_process(COMMAND ${REPORT} --dataset ${OUT}/office --scans 2 --first 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE from_folder ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT from_folder MATCHES "\nscan 1 +[0-9]+ +[0-9]+ +0\\.[0-9]+ +0\\.[0-9]+"
   OR NOT from_folder MATCHES "\nscan 2 ")
  message(FATAL_ERROR "ctlio_geometry_report --dataset (${rc}):\n${from_folder}\n${err}")
endif()
execute_process(COMMAND ${SIMULATE} --world office --regime walking --duration 0.3 --beams 32
                        --firing_decimation 4 --geometry_report 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE from_memory ERROR_VARIABLE err)
# The same numbers from the folder (float32 points) and from memory, to the printed digits.
string(REGEX MATCH "scan 1 +([0-9]+ +[0-9]+ +[0-9.]+ +[0-9.]+)" m1 "${from_folder}")
set(a "${CMAKE_MATCH_1}")
string(REGEX MATCH "scan 1 +([0-9]+ +[0-9]+ +[0-9.]+ +[0-9.]+)" m2 "${from_memory}")
set(b "${CMAKE_MATCH_1}")
if(NOT rc EQUAL 0 OR a STREQUAL "" OR NOT a STREQUAL b)
  message(FATAL_ERROR "folder '${a}' vs memory '${b}' (${rc}):\n${from_memory}\n${err}")
endif()
execute_process(COMMAND ${REPORT} --cloud ${OUT}/no_such.bin RESULT_VARIABLE rc
                ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "no_such.bin")
  message(FATAL_ERROR "a missing file must be an error naming it (${rc}):\n${err}")
endif()
