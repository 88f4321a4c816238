# Runs `pathbench render ARGS...` and checks what bad input must give: exit status 2,
# a message matching EXPECT on stderr, and no image at OUT nor report at REPORT
# (ARGS name them with --out and --report).
#   cmake -DPATHBENCH=<exe> -DOUT=<image> -DREPORT=<report> -DEXPECT=<regex> "-DARGS=a;b;c"
#         [-DSTATUS=0 -DOUT_MUST_EXIST=ON] -P expect_bad_input.cmake
# (STATUS/OUT_MUST_EXIST flip it round for the cases that must succeed.)
include(${CMAKE_CURRENT_LIST_DIR}/run_pathbench.cmake)
file(REMOVE "${OUT}" "${REPORT}")
run_pathbench(render --quiet ${ARGS})
if(OUT_MUST_EXIST)
  foreach(f "${OUT}" "${REPORT}")
    if(NOT EXISTS "${f}")
      string(APPEND failed "${f} was not written\n")
    endif()
  endforeach()
  file(REMOVE "${OUT}" "${REPORT}")
else()
  # The files, or their temporaries (OutputFile: .NAME.XXXXXX.tmp beside them).
  set(globs)
  foreach(f "${OUT}" "${REPORT}")
    get_filename_component(dir "${f}" DIRECTORY)
    get_filename_component(name "${f}" NAME)
    list(APPEND globs "${f}" "${dir}/.${name}.*.tmp")
  endforeach()
  file(GLOB leftovers LIST_DIRECTORIES true ${globs})
  if(leftovers)
    string(APPEND failed "${leftovers} written although the input was bad\n")
  endif()
endif()
if(failed)
  message(FATAL_ERROR "pathbench render ${ARGS}\n${failed}--- stderr:\n${err}--- stdout:\n${out}")
endif()
