# Runs ctlio_simulate --sensor (used by sim.Simulate.SensorFlags): `list` prints one line per
# model; a sensor sets beams, firings and IMU rate, an explicit --duration still applies; an
# unknown name and a --beams that contradicts a datasheet table are errors naming the flag's value.
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${EXE} --sensor list RESULT_VARIABLE rc OUTPUT_VARIABLE out)
string(REGEX MATCHALL "\n" lines "${out}")
list(LENGTH lines n)
if(NOT rc EQUAL 0 OR NOT n EQUAL 8)
  message(FATAL_ERROR "--sensor list: exit ${rc}, ${n} lines:\n${out}")
endif()
execute_process(
  COMMAND ${EXE} --sensor hdl32e --duration 0.2 --firing_decimation 50 --output ${OUT}/hdl
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_simulate failed (${rc}):\n${out}\n${err}")
endif()
file(READ ${OUT}/hdl/ctlio_sim.yaml meta)
foreach(field "sensor: hdl32e" "beams: 32," "firings_per_revolution: 2170" "imu_rate_hz: 400,"
        "duration_s: 0.2,")
  string(FIND "${meta}" "${field}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "ctlio_sim.yaml lacks '${field}':\n${meta}")
  endif()
endforeach()
foreach(bad "--sensor;vlp32" "--sensor;vlp16;--beams;32")
  execute_process(COMMAND ${EXE} ${bad} --duration 0.2 --output ${OUT}/bad
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0 OR NOT err MATCHES "vlp")
    message(FATAL_ERROR "${bad}: expected an error naming the sensor, got ${rc}:\n${err}")
  endif()
endforeach()
