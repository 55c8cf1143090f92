# fast_float is header-only (Debian: libfast-float-dev, include <fast_float/fast_float.h>).
find_path(PATCHSKIN_FAST_FLOAT_INCLUDE_DIR fast_float/fast_float.h REQUIRED)
add_library(patchskin_fast_float INTERFACE)
target_include_directories(patchskin_fast_float SYSTEM INTERFACE ${PATCHSKIN_FAST_FLOAT_INCLUDE_DIR})
