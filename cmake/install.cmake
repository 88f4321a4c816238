# Install rules of the command line and its Python tools (the module's own rule is in
# python/CMakeLists.txt). Under scikit-build-core (`pip install .`) the binaries go to the
# environment's scripts folder and the tools to its data folder (<venv>/bin, <venv>/share),
# so the same relative layout holds: bin/pathbench -> ../share/pathbench/tools.
include(GNUInstallDirs)
if(SKBUILD)
  set(pathbench_install_bindir "${SKBUILD_SCRIPTS_DIR}")
  set(pathbench_install_datadir "${SKBUILD_DATA_DIR}/share")
else()
  set(pathbench_install_bindir "${CMAKE_INSTALL_BINDIR}")
  set(pathbench_install_datadir "${CMAKE_INSTALL_DATADIR}")
endif()
foreach(t pathbench pathbench-bench)
  if(TARGET ${t})
    install(TARGETS ${t} RUNTIME DESTINATION "${pathbench_install_bindir}" COMPONENT cli)
  endif()
endforeach()
install(DIRECTORY "${PROJECT_SOURCE_DIR}/tools/" DESTINATION "${pathbench_install_datadir}/pathbench/tools" COMPONENT cli
        FILES_MATCHING PATTERN "*.py" PATTERN "*.md" PATTERN "*.css" PATTERN "*.js" PATTERN "requirements*.txt"
        PATTERN "__pycache__" EXCLUDE PATTERN "isa_cap" EXCLUDE)
# The project's history export (the reference machines' runs), which `history changes` and
# `report` build the per-user database from on first use (tools/history/cli.py).
install(DIRECTORY "${PROJECT_SOURCE_DIR}/results/history/runs/"
        DESTINATION "${pathbench_install_datadir}/pathbench/results/history/runs" COMPONENT cli
        FILES_MATCHING PATTERN "*.jsonl")
