# Runs one program of examples/c on its simulated robot with RCCX_LOG set, and checks that it
# exits 0 (each program checks the geometry it asked for and exits 1 when it is off), prints
# what EXPECT matches, and logged samples.
# With -DREAL_TIME=ON (a program in real time), a run ended by an overrun is made again (three
# in all). Three overruns while the process could not get SCHED_FIFO are no verdict on rccx but
# on the machine's load: the test says so and is skipped ("SKIP: ", the test's
# SKIP_REGULAR_EXPRESSION); with SCHED_FIFO they fail.
#   cmake -DPROG=path -DLOG=out.csv -DEXPECT=regex [-DINPUT=file] [-DDB=file] [-DFRESH_DB=ON]
#         [-DROBOT=name (RCCX_ROBOT)] [-DREAL_TIME=ON]
#         -P c_example_test.cmake
foreach(var PROG LOG EXPECT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "c_example_test.cmake needs -D${var}=...")
  endif()
endforeach()
file(REMOVE "${LOG}")
set(ENV{RCCX_LOG} "${LOG}")
if(DEFINED ROBOT)
  set(ENV{RCCX_ROBOT} "${ROBOT}")
endif()
if(DEFINED DB)
  if(FRESH_DB)
    file(REMOVE "${DB}")
  endif()
  set(ENV{RCCX_DB} "${DB}")
endif()
if(NOT DEFINED INPUT)
  set(INPUT /dev/null)
endif()
# In real time a run that a loaded machine ended by an overrun is made again (three runs in all),
# on a fresh log and database, before any verdict.
foreach(attempt RANGE 1 3)
  if(attempt GREATER 1)
    message(STATUS "control overran its period: run ${attempt} of 3")
    file(REMOVE "${LOG}")
    if(DEFINED DB AND FRESH_DB)
      file(REMOVE "${DB}")
    endif()
  endif()
  execute_process(COMMAND "${PROG}" INPUT_FILE "${INPUT}" RESULT_VARIABLE rc
                  OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
  message(STATUS "stdout:\n${out}")
  if(NOT err STREQUAL "")
    message(STATUS "stderr:\n${err}")
  endif()
  if(NOT REAL_TIME OR rc STREQUAL "0" OR NOT "${out}${err}" MATCHES "with overrun")
    break()
  endif()
endforeach()
if(REAL_TIME AND NOT rc STREQUAL "0" AND err MATCHES "SCHED_FIFO not permitted"
   AND "${out}${err}" MATCHES "with overrun")
  message(STATUS "SKIP: control overran its period, and this process may not use SCHED_FIFO "
                 "(not root, no CAP_SYS_NICE or rtprio limit): on a loaded machine that is the "
                 "scheduler's doing, not rccx's. Run the tests as root (or grant an rtprio "
                 "limit) for a real-time verdict.")
  return()
endif()
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "${PROG} exited with ${rc}")
endif()
if(NOT out MATCHES "${EXPECT}")
  message(FATAL_ERROR "${PROG} did not print what matches \"${EXPECT}\"")
endif()
file(STRINGS "${LOG}" rows)
list(LENGTH rows n)
if(n LESS 10)
  message(FATAL_ERROR "${LOG} has ${n} rows: the session was not logged")
endif()
