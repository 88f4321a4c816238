# Runs `pathbench render ARGS...` and checks what bad input must give: exit status 2,
# a message matching EXPECT on stderr, and no image at OUT nor report at REPORT
# (ARGS name them with --out and --report).
#   cmake -DPATHBENCH=<exe> -DOUT=<image> -DREPORT=<report> -DEXPECT=<regex> "-DARGS=a;b;c"
#         [-DSTATUS=0 -DOUT_MUST_EXIST=ON] -P expect_bad_input.cmake
# (STATUS/OUT_MUST_EXIST flip it round for the cases that must succeed.)
if(NOT DEFINED STATUS)
  set(STATUS 2)
endif()
file(REMOVE "${OUT}" "${REPORT}")
execute_process(COMMAND "${PATHBENCH}" render --quiet ${ARGS}
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(failed "")
if(NOT status STREQUAL "${STATUS}")
  string(APPEND failed "exit status ${status}, expected ${STATUS}\n")
endif()
if(NOT err MATCHES "${EXPECT}")
  string(APPEND failed "stderr does not match '${EXPECT}'\n")
endif()
if(OUT_MUST_EXIST)
  foreach(f "${OUT}" "${REPORT}")
    if(NOT EXISTS "${f}")
      string(APPEND failed "${f} was not written\n")
    endif()
  endforeach()
  file(REMOVE "${OUT}" "${REPORT}")
else()
  # The files, or their temporaries.
  file(GLOB leftovers "${OUT}" "${OUT}.tmp*" "${REPORT}" "${REPORT}.tmp*")
  if(leftovers)
    string(APPEND failed "${leftovers} written although the input was bad\n")
  endif()
endif()
if(failed)
  message(FATAL_ERROR "pathbench render ${ARGS}\n${failed}--- stderr:\n${err}--- stdout:\n${out}")
endif()
