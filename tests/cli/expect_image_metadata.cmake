# Renders a tiny image to OUT (.exr or .png) and checks that its header carries the
# metadata a result is reproduced from: scene, spp, seed, settings and commit (EXR
# string attributes and PNG text chunks both hold the plain text).
#   cmake -DPATHBENCH=<exe> -DOUT=<image> -P expect_image_metadata.cmake
file(REMOVE "${OUT}")
execute_process(COMMAND "${PATHBENCH}" render --quiet --scene paper-cornell --width 8 --height 8 --spp 3 --seed 77
                        --out "${OUT}" RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "render failed (${rc}): ${err}")
endif()
file(READ "${OUT}" bytes HEX)
foreach(text "pathbench:scene" "paper-cornell" "pathbench:spp" "pathbench:seed" "77" "pathbench:settings"
             "\"sampling\":\"nee\"" "pathbench:commit" "Software")
  string(HEX "${text}" hex)
  string(FIND "${bytes}" "${hex}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${OUT}: no '${text}' in the image's header")
  endif()
endforeach()
file(REMOVE "${OUT}")
