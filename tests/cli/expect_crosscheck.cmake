# `pathbench crosscheck`: paper-cornell against its own Mitsuba export passes (exit 0),
# and against the same export with the red wall's albedo halved fails (exit 1, FAIL).
# Skipped (77) where the tree's .venv has no Mitsuba 3.
#   cmake -DPATHBENCH=<exe> -DOUT_DIR=<dir> -P expect_crosscheck.cmake
file(REMOVE_RECURSE "${OUT_DIR}")
set(common --spp 64 --width 32 --height 24 --device cpu)
execute_process(COMMAND "${PATHBENCH}" crosscheck paper-cornell --out-dir "${OUT_DIR}/right" ${common}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 2 AND err MATCHES "Mitsuba 3 is not installed")
  message("SKIP: ${err}")
  return()
endif()
if(NOT rc EQUAL 0 OR NOT out MATCHES "cpu: PASS" OR NOT EXISTS "${OUT_DIR}/right/diff-cpu.pfm"
   OR NOT EXISTS "${OUT_DIR}/right/verdict.json")
  message(FATAL_ERROR "crosscheck of paper-cornell should pass (exit ${rc}):\n${out}\n${err}")
endif()
file(READ "${OUT_DIR}/right/mitsuba/scene.xml" xml)
string(REPLACE "value=\"0.5, 0, 0\"" "value=\"0.25, 0, 0\"" wrong "${xml}")
if(wrong STREQUAL xml)
  message(FATAL_ERROR "no red wall (reflectance 0.5, 0, 0) in the exported scene:\n${xml}")
endif()
file(WRITE "${OUT_DIR}/right/mitsuba/wrong.xml" "${wrong}")
execute_process(COMMAND "${PATHBENCH}" crosscheck paper-cornell --mitsuba-xml "${OUT_DIR}/right/mitsuba/wrong.xml"
                        --out-dir "${OUT_DIR}/wrong" ${common}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT out MATCHES "cpu: FAIL" OR NOT out MATCHES "DIFFERENT")
  message(FATAL_ERROR "crosscheck against a wrong albedo should fail with exit 1 (exit ${rc}):\n${out}\n${err}")
endif()
