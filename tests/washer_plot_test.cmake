# Runs examples/04_washer with RCCX_LOG and `rccx plot` on its log: both must print the same
# worst path error (the measured tool from the commanded path, every sample; issue 24: the
# washer said 4.541 mm of the straight edges and the plot 4.870 mm without saying they differ),
# and the log's header must name the Microbo.
#   cmake -DWASHER=04_washer -DRCCX=rccx -DLOG=out.csv -P washer_plot_test.cmake
foreach(var WASHER RCCX LOG)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "washer_plot_test.cmake needs -D${var}=...")
  endif()
endforeach()

file(REMOVE "${LOG}")
set(ENV{RCCX_LOG} "${LOG}")
execute_process(COMMAND "${WASHER}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                TIMEOUT 600)
unset(ENV{RCCX_LOG})
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "04_washer exited with ${rc}:\n${out}\n${err}")
endif()
set(figure "worst path error ([0-9]+\\.[0-9]+) mm \\(measured tool from the commanded path")
if(NOT out MATCHES "log [^\n]*: ${figure}")
  message(FATAL_ERROR "04_washer did not print the log's worst path error:\n${out}")
endif()
set(washer "${CMAKE_MATCH_1}")

file(STRINGS "${LOG}" header LIMIT_COUNT 1)
if(NOT header MATCHES "^# rccx-log 1 robot=microbo .*name=microbo ")
  message(FATAL_ERROR "the log's header does not name the Microbo: ${header}")
endif()

execute_process(COMMAND "${RCCX}" plot "${LOG}" -o "${LOG}.svg" RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "rccx plot exited with ${rc}:\n${out}\n${err}")
endif()
if(NOT out MATCHES "${figure}")
  message(FATAL_ERROR "rccx plot did not print its worst path error:\n${out}")
endif()
if(NOT CMAKE_MATCH_1 STREQUAL washer)
  message(FATAL_ERROR "04_washer says ${washer} mm, rccx plot ${CMAKE_MATCH_1} mm")
endif()
message(STATUS "04_washer and rccx plot agree: worst path error ${washer} mm")
file(REMOVE "${LOG}" "${LOG}.svg")
