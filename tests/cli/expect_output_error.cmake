# An output path pathbench cannot use: exit status 2, one line on stderr matching
# EXPECT (and short: a long name is shortened), and nothing written -- the case's
# folder holds afterwards exactly what SETUP put there (no image, no report, no
# .NAME.XXXXXX.tmp), since every output path is checked before the render.
#   cmake -DPATHBENCH=<exe> -DDIR=<fresh folder> -DSETUP=<kind> -DEXPECT=<regex>
#         "-DARGS=render;--out;@DIR@/x.png;..." -P expect_output_error.cmake
# @DIR@ in ARGS is replaced by DIR. SETUP: none, dir:NAME (a folder), file:NAME (a
# regular file), loop:A:B (symbolic links A -> B -> A).
include(${CMAKE_CURRENT_LIST_DIR}/run_pathbench.cmake)
file(REMOVE_RECURSE "${DIR}")
file(MAKE_DIRECTORY "${DIR}")
foreach(item ${SETUP})
  string(REPLACE ":" ";" parts "${item}")
  list(GET parts 0 kind)
  if(kind STREQUAL "dir")
    list(GET parts 1 name)
    file(MAKE_DIRECTORY "${DIR}/${name}")
  elseif(kind STREQUAL "file")
    list(GET parts 1 name)
    file(WRITE "${DIR}/${name}" "")
  elseif(kind STREQUAL "loop")
    list(GET parts 1 a)
    list(GET parts 2 b)
    file(CREATE_LINK "${b}" "${DIR}/${a}" SYMBOLIC)
    file(CREATE_LINK "${a}" "${DIR}/${b}" SYMBOLIC)
  endif()
endforeach()
file(GLOB_RECURSE before LIST_DIRECTORIES true "${DIR}/*" "${DIR}/.*")

string(REPLACE "@DIR@" "${DIR}" args "${ARGS}")
run_pathbench(${args})

string(REGEX REPLACE "\n$" "" body "${err}")
if(body MATCHES "\n")
  string(APPEND failed "stderr has more than one line\n")
endif()
string(LENGTH "${err}" err_length)
if(err_length GREATER 400)
  string(APPEND failed "stderr is ${err_length} bytes long (a long name must be shortened)\n")
endif()
if(NOT err MATCHES "^pathbench: error: ")
  string(APPEND failed "stderr does not start with 'pathbench: error: '\n")
endif()
file(GLOB_RECURSE after LIST_DIRECTORIES true "${DIR}/*" "${DIR}/.*")
if(NOT before STREQUAL after)
  string(APPEND failed "the folder changed:\nbefore: ${before}\nafter:  ${after}\n")
endif()
if(failed)
  string(SUBSTRING "${args}" 0 600 shown)
  message(FATAL_ERROR "pathbench ${shown}\n${failed}--- stderr:\n${err}--- stdout:\n${out}")
endif()
