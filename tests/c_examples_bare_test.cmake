# Every program of examples/c run as a newcomer runs it: no arguments, no RCCX_* variables,
# standard input at its end, in an empty directory. Each must run (exit 0) or say on stderr
# how to run it ("usage:") and exit 2. Then README.md and docs/RCCL.md must name every program
# of the folder, and README.md must give their number.
#   cmake -DBIN_DIR=dir -DSRC_DIR=examples/c -DREADME=README.md -DRCCL_MD=docs/RCCL.md
#         -DWORK=dir -P c_examples_bare_test.cmake
foreach(var BIN_DIR SRC_DIR README RCCL_MD WORK)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "c_examples_bare_test.cmake needs -D${var}=...")
  endif()
endforeach()
file(GLOB sources RELATIVE "${SRC_DIR}" "${SRC_DIR}/*.c")
list(SORT sources)
list(LENGTH sources count)
foreach(var RCCX_ROBOT RCCX_LOG RCCX_DB RCCX_CELL)
  unset(ENV{${var}})
endforeach()
set(failures "")
set(overran "")
set(overrun_said "control ended at sample [0-9]+ [^\n]* with overrun")  # RTC's terminate line
foreach(source ${sources})
  string(REGEX REPLACE "\\.c$" "" name "${source}")
  file(REMOVE_RECURSE "${WORK}/${name}")
  file(MAKE_DIRECTORY "${WORK}/${name}")
  # Programs in real time (the default clock) on a loaded machine can end control by an
  # overrun: a verdict on the machine, not on how the program greets a newcomer. Such a run is
  # made again, up to three times; three overruns skip the test, saying so, when nothing else
  # failed (real-time verdicts are c_example_*_real's).
  foreach(attempt RANGE 1 3)
    execute_process(COMMAND "${BIN_DIR}/c_${name}" WORKING_DIRECTORY "${WORK}/${name}"
                    INPUT_FILE /dev/null RESULT_VARIABLE rc OUTPUT_VARIABLE out
                    ERROR_VARIABLE err TIMEOUT 300)
    message(STATUS "c_${name}: exit ${rc}")
    if(rc STREQUAL "0" OR NOT "${out}${err}" MATCHES "${overrun_said}")
      break()
    endif()
    message(STATUS "  its control overran its period (run ${attempt} of 3):\n${out}\n${err}")
  endforeach()
  if(NOT rc STREQUAL "0" AND "${out}${err}" MATCHES "${overrun_said}")
    list(APPEND overran "c_${name}")
    continue()
  endif()
  if(rc STREQUAL "0")
    continue()
  elseif(rc STREQUAL "2" AND err MATCHES "usage: ")
    message(STATUS "  says what it needs:\n${err}")
  else()
    list(APPEND failures "c_${name} exited ${rc} without a usage line:\n${out}\n${err}")
  endif()
endforeach()
set(words zero one two three four five six seven eight nine ten eleven twelve thirteen fourteen
    fifteen sixteen)
list(GET words ${count} word)
file(READ "${README}" readme)
file(READ "${RCCL_MD}" rccl_md)
if(NOT readme MATCHES "`examples/c/` holds ${word} programs")
  list(APPEND failures "README.md does not say \"`examples/c/` holds ${word} programs\"")
endif()
if(NOT rccl_md MATCHES "`examples/c/` has ${word} programs")
  list(APPEND failures "docs/RCCL.md does not say \"`examples/c/` has ${word} programs\"")
endif()
foreach(source ${sources})
  foreach(doc readme rccl_md)
    string(FIND "${${doc}}" "`${source}`" at)
    if(at EQUAL -1)
      list(APPEND failures "${doc} does not name `${source}`")
    endif()
  endforeach()
endforeach()
if(failures)
  string(REPLACE ";" "\n" failures "${failures}")
  message(FATAL_ERROR "${failures}")
endif()
if(overran)
  string(REPLACE ";" ", " overran "${overran}")
  message(STATUS "SKIP: control overran its period in three runs each of ${overran} (real time "
                 "on a loaded machine): every other check of this test held")
endif()
