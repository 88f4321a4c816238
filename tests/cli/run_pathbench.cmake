# Shared by the cli check scripts: runs `pathbench <args...>` and starts the list of
# failures with the two checks every case makes -- the exit status is STATUS (default
# 2, bad input) and stderr matches EXPECT. Sets status, out, err and failed.
macro(run_pathbench)
  if(NOT DEFINED STATUS)
    set(STATUS 2)
  endif()
  execute_process(COMMAND "${PATHBENCH}" ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(failed "")
  if(NOT status STREQUAL "${STATUS}")
    string(APPEND failed "exit status ${status}, expected ${STATUS}\n")
  endif()
  if(NOT err MATCHES "${EXPECT}")
    string(APPEND failed "stderr does not match '${EXPECT}'\n")
  endif()
endmacro()
