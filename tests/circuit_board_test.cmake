# Runs examples/10_circuit_board (the two-robot circuit-board demo on the CVaRL cell) and checks
# that it exits 0, prints its table of probed pads and a summary without failures or collision
# stops, and writes one CSV row per pad.
#   cmake -DDEMO=path/to/10_circuit_board -DCSV=out.csv -DPADS=8 -P circuit_board_test.cmake
foreach(var DEMO CSV PADS)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "circuit_board_test.cmake needs -D${var}=...")
  endif()
endforeach()

file(REMOVE "${CSV}")
execute_process(COMMAND "${DEMO}" --csv "${CSV}" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err TIMEOUT 300)
message(STATUS "10_circuit_board stdout:\n${out}")
if(NOT err STREQUAL "")
  message(STATUS "10_circuit_board stderr:\n${err}")
endif()
if(NOT rc STREQUAL "0")
  message(FATAL_ERROR "10_circuit_board exited with ${rc}")
endif()
foreach(text " pad   x mm   y mm  board" "failures: PUMA none, Microbo none; collision stops 0"
        "${PADS} pads probed")
  string(FIND "${out}" "${text}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "10_circuit_board did not print \"${text}\"")
  endif()
endforeach()
# At least two pads probed while the PUMA moved the board (the table says its speed).
string(REGEX MATCHALL "[0-9.]+ mm/s +[0-9]" moving "${out}")
list(LENGTH moving n_moving)
if(n_moving LESS 2)
  message(FATAL_ERROR "only ${n_moving} pads were probed on the moving board, expected 2 or more")
endif()

if(NOT EXISTS "${CSV}")
  message(FATAL_ERROR "--csv ${CSV} was not written")
endif()
file(STRINGS "${CSV}" rows)
list(POP_FRONT rows header)
if(NOT header MATCHES "^pad,x_mm,y_mm,")
  message(FATAL_ERROR "the CSV's header is \"${header}\", not pad,x_mm,y_mm,...")
endif()
list(LENGTH rows n)
if(NOT n EQUAL PADS)
  message(FATAL_ERROR "the CSV has ${n} rows, expected ${PADS}")
endif()
message(STATUS "10_circuit_board: exit 0, table, ${n_moving} pads on the moving board, ${n} CSV rows")
