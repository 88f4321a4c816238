# FindNCCL: NVIDIA's collective library (nccl.h, libnccl.so.2), for the GPU ranks' film
# reduction on the GPUs (run/, issue 30). Looked for in NCCL_ROOT / $NCCL_ROOT / $NCCL_HOME,
# CMake's prefixes, the system, and the PyPI wheel's folder (nvidia-nccl-cu13 / -cu12:
# site-packages/nvidia/nccl/{include,lib}) of this checkout's .venv and of the Python
# environments that ship it (PyTorch's on the GPU hosts: /opt/torch/.venv).
# Defines NCCL_FOUND, NCCL_INCLUDE_DIR, NCCL_LIBRARY, NCCL_VERSION and the imported
# target NCCL::nccl.
set(_nccl_hints ${NCCL_ROOT} $ENV{NCCL_ROOT} $ENV{NCCL_HOME})
file(GLOB _nccl_wheels
     "${CMAKE_SOURCE_DIR}/.venv/lib/python3*/site-packages/nvidia/nccl"
     "/opt/torch/.venv/lib/python3*/site-packages/nvidia/nccl"
     "/usr/local/lib/python3*/dist-packages/nvidia/nccl"
     "/usr/lib/python3/dist-packages/nvidia/nccl")
list(APPEND _nccl_hints ${_nccl_wheels})
find_path(NCCL_INCLUDE_DIR nccl.h HINTS ${_nccl_hints} PATH_SUFFIXES include)
# The wheel ships libnccl.so.2 alone (no libnccl.so link): name it too.
find_library(NCCL_LIBRARY NAMES nccl libnccl.so.2 NAMES_PER_DIR HINTS ${_nccl_hints} PATH_SUFFIXES lib lib64)
if(NCCL_INCLUDE_DIR AND EXISTS "${NCCL_INCLUDE_DIR}/nccl.h")
  file(STRINGS "${NCCL_INCLUDE_DIR}/nccl.h" _nccl_v REGEX "^#define NCCL_(MAJOR|MINOR|PATCH) +[0-9]+")
  string(REGEX REPLACE ".*NCCL_MAJOR +([0-9]+).*" "\\1" _nccl_major "${_nccl_v}")
  string(REGEX REPLACE ".*NCCL_MINOR +([0-9]+).*" "\\1" _nccl_minor "${_nccl_v}")
  string(REGEX REPLACE ".*NCCL_PATCH +([0-9]+).*" "\\1" _nccl_patch "${_nccl_v}")
  set(NCCL_VERSION "${_nccl_major}.${_nccl_minor}.${_nccl_patch}")
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(NCCL REQUIRED_VARS NCCL_LIBRARY NCCL_INCLUDE_DIR VERSION_VAR NCCL_VERSION)
if(NCCL_FOUND AND NOT TARGET NCCL::nccl)
  add_library(NCCL::nccl UNKNOWN IMPORTED)
  set_target_properties(NCCL::nccl PROPERTIES IMPORTED_LOCATION "${NCCL_LIBRARY}"
                                              INTERFACE_INCLUDE_DIRECTORIES "${NCCL_INCLUDE_DIR}")
endif()
mark_as_advanced(NCCL_INCLUDE_DIR NCCL_LIBRARY)
