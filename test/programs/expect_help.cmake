cmake_minimum_required(VERSION 3.25)
# The help of a program (apps/common/command_line.h). Passes if
#   EXE --help and EXE --helpshort exit 0 with stdout starting "NAME:" (the usage line), listing
#     the program's own flag --OWN, at least as many flags as SOURCE defines, none of the logging
#     flags;
#   EXE --helpfull exits 0 and lists gflags' flags (flagfile) and, if GLOG is set, glog's;
#   EXE --no_such_flag exits non-zero naming the flag on stderr.
foreach(help --help --helpshort)
  execute_process(COMMAND ${EXE} ${help} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err TIMEOUT 60)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${NAME} ${help}: exit ${rc}, expected 0:\n${out}\n${err}")
  endif()
  string(FIND "${out}" "${NAME}:" at)
  if(NOT at EQUAL 0)
    message(FATAL_ERROR "${NAME} ${help}: stdout does not start with '${NAME}:':\n${out}")
  endif()
  string(FIND "${out}" "\n  --${OWN}=" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${NAME} ${help}: its own flag --${OWN} is not listed:\n${out}")
  endif()
  # Every flag the program's source defines (flags of the project's headers and libraries that the
  # program links are its own too, so there may be more).
  file(READ ${SOURCE} source_text)
  string(REGEX MATCHALL "\nDEFINE_" defines "${source_text}")
  list(LENGTH defines expected_flags)
  string(REGEX MATCHALL "\n  --[a-z0-9_]+=" listed "${out}")
  list(LENGTH listed listed_flags)
  if(listed_flags LESS expected_flags)
    message(FATAL_ERROR "${NAME} ${help}: ${listed_flags} flags listed, ${SOURCE} defines "
                        "${expected_flags}:\n${out}")
  endif()
  foreach(foreign logtostderr flagfile helpfull)
    string(FIND "${out}" "--${foreign}=" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "${NAME} ${help}: lists --${foreign} (only --helpfull should):\n${out}")
    endif()
  endforeach()
endforeach()

execute_process(COMMAND ${EXE} --helpfull RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err TIMEOUT 60)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${NAME} --helpfull: exit ${rc}, expected 0:\n${err}")
endif()
set(expected flagfile ${OWN})
if(GLOG)
  list(APPEND expected logtostderr)
endif()
foreach(flag ${expected})
  string(FIND "${out}" "-${flag} (" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${NAME} --helpfull does not list -${flag}:\n${out}")
  endif()
endforeach()

execute_process(COMMAND ${EXE} --no_such_flag RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err TIMEOUT 60)
if(rc EQUAL 0 OR NOT rc MATCHES "^[0-9]+$")
  message(FATAL_ERROR "${NAME} --no_such_flag: exit ${rc}, expected a non-zero exit:\n${out}")
endif()
string(FIND "${err}" "unknown command line flag 'no_such_flag'" at)
if(at EQUAL -1)
  message(FATAL_ERROR "${NAME} --no_such_flag: no message naming the flag:\n${err}")
endif()
