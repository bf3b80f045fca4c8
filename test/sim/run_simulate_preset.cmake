# Runs ctlio_simulate with --preset newer_college and explicit flags and checks the recorded
# settings (used by sim.Simulate.PresetFlags): the preset sets firings, IMU rate, world and
# regime; an explicit --beams / --regime wins over it.
file(REMOVE_RECURSE ${OUT})
execute_process(
  COMMAND ${EXE} --preset newer_college --beams 16 --duration 0.3 --firing_decimation 16
          --output ${OUT}/preset
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_simulate failed (${rc}):\n${out}\n${err}")
endif()
file(READ ${OUT}/preset/ctlio_sim.yaml meta)
foreach(field "preset: newer_college" "world: quad" "regime: walking" "beams: 16,"
        "firings_per_revolution: 1024" "imu_rate_hz: 100," "lidar_rate_hz: 10,")
  string(FIND "${meta}" "${field}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "ctlio_sim.yaml lacks '${field}':\n${meta}")
  endif()
endforeach()
execute_process(
  COMMAND ${EXE} --preset newer_college --regime vehicle --world street --duration 0.3
          --firing_decimation 16 --output ${OUT}/override
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "ctlio_simulate failed (${rc}):\n${out}\n${err}")
endif()
file(READ ${OUT}/override/ctlio_sim.yaml meta)
foreach(field "world: street" "regime: vehicle" "beams: 64," "imu_rate_hz: 100,")
  string(FIND "${meta}" "${field}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "ctlio_sim.yaml lacks '${field}':\n${meta}")
  endif()
endforeach()
