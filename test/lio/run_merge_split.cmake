# Split jobs pooled by `ctlio_experiment --merge` give the table of one job over the same runs
# (used by lio.Experiment.MergeSplitJobs): two jobs of one sequence each, one job of both, at a
# tiny size; the pooled RMSE and failures (pooled.csv) must be equal, and merging a job with
# itself must be refused.
file(REMOVE_RECURSE ${OUT})
set(common --regimes slow,fast --methods singer_lio,lidar_only --duration 0.6 --beams 16
           --firing_decimation 8 --threads 1)
foreach(job "a;0;1" "b;1;1" "all;0;2")
  list(GET job 0 name)
  list(GET job 1 first)
  list(GET job 2 count)
  execute_process(COMMAND ${EXE} --out ${OUT}/${name} --first_sequence ${first}
                          --sequences ${count} ${common}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "job ${name} failed (${rc}):\n${out}\n${err}")
  endif()
endforeach()
execute_process(COMMAND ${EXE} --merge ${OUT}/a,${OUT}/b --out ${OUT}/merged
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "merge failed (${rc}):\n${out}\n${err}")
endif()
file(READ ${OUT}/all/pooled.csv single)
file(READ ${OUT}/merged/pooled.csv merged)
if(NOT single STREQUAL merged)
  message(FATAL_ERROR "pooled results differ:\nsingle job:\n${single}\nmerged:\n${merged}")
endif()
string(REGEX MATCHALL "\n" newlines "${merged}")
list(LENGTH newlines n)
if(NOT n EQUAL 5)  # header + 2 regimes × 2 methods
  message(FATAL_ERROR "pooled.csv has ${n} lines, expected 5:\n${merged}")
endif()
execute_process(COMMAND ${EXE} --merge ${OUT}/a,${OUT}/a --out ${OUT}/twice
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(FIND "${err}" "appears in more than one job" at)
if(rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "merging a job with itself was not refused (${rc}):\n${err}")
endif()
