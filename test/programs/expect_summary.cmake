cmake_minimum_required(VERSION 3.25)
# ctlio_odometry's run summary (EXE, a tiny simulated run in WORK, stderr not a terminal):
# it says which config it used, the progress comes as whole lines (no '\r'), the table's two
# degenerate counts are evaluation.txt's degenerate_scans and degenerate_direction_scans, and the
# files written are listed.
file(REMOVE_RECURSE ${WORK})
execute_process(COMMAND ${EXE} --format=sim --sim_duration=0.6 --sim_beams=8
                        --sim_firing_decimation=60 --method=lidar_only,lidar_gyro
                        --plot=false
                        --out=${WORK}/out
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT rc MATCHES "^[01]$")  # 1: the run failed (a tiny run may), still summarised
  message(FATAL_ERROR "exit ${rc}:\n${out}\n${err}")
endif()
string(FIND "${out}" "config: built-in defaults (no --config)\n" at)
if(at EQUAL -1)
  message(FATAL_ERROR "no line saying the built-in defaults are used:\n${out}")
endif()
string(FIND "${err}" "\r" at)
if(NOT at EQUAL -1)
  message(FATAL_ERROR "progress with '\\r' although stderr is not a terminal:\n${err}")
endif()
# Per method, each with its own tenths: with at most 10 scans every scan starts another tenth.
foreach(method lidar_only lidar_gyro)
  string(REGEX MATCHALL "\\[${method}\\] scan [0-9]+/([0-9]+) [^\n]*\n" progress "${err}")
  set(total ${CMAKE_MATCH_1})
  list(LENGTH progress lines)
  if(total STREQUAL "" OR total GREATER 10 OR NOT lines EQUAL total)
    message(FATAL_ERROR "${method}: expected one progress line per scan of ${total}, got "
                        "${lines}:\n${err}")
  endif()
endforeach()
file(READ ${WORK}/out/lidar_only/evaluation.txt ev)
string(REGEX MATCH "\ndegenerate_scans ([0-9]+)\n" _ "${ev}")
set(degenerate ${CMAKE_MATCH_1})
string(REGEX MATCH "\ndegenerate_direction_scans ([0-9]+)\n" _ "${ev}")
set(directions ${CMAKE_MATCH_1})
string(REGEX MATCH "\nscans ([0-9]+)\n" _ "${ev}")
set(scans ${CMAKE_MATCH_1})
if(degenerate STREQUAL "" OR directions STREQUAL "" OR scans STREQUAL "")
  message(FATAL_ERROR "evaluation.txt lacks the scan counts:\n${ev}")
endif()
# The table's row: method ATE mean max drift scans failed degenerate degen_dir.
string(REGEX MATCH "\nlidar_only +[-0-9.]+ +[-0-9.]+ +[-0-9.]+ +[-0-9.]+ +([0-9]+) +[0-9]+ +([0-9]+) +([0-9]+)\n"
       row "${out}")
if(NOT row OR NOT CMAKE_MATCH_1 EQUAL scans OR NOT CMAKE_MATCH_2 EQUAL degenerate
   OR NOT CMAKE_MATCH_3 EQUAL directions)
  message(FATAL_ERROR "the summary's scans/degenerate/degen_dir differ from evaluation.txt's "
                      "(${scans}/${degenerate}/${directions}):\n${out}")
endif()
foreach(text "degenerate_scans" "degenerate_direction_scans" "wall_med" "peak[MB]"
             "Files written:\n" "/out/lidar_only/trajectory.tum " "/out/lidar_only/scans.log "
             "/out/lidar_only/evaluation.txt " "/out/lidar_gyro/evaluation.txt ")
  string(FIND "${out}" "${text}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the summary lacks '${text}':\n${out}")
  endif()
endforeach()
