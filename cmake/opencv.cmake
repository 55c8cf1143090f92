# Debian splits OpenCV into per-module -dev packages; only the meta package
# libopencv-dev ships OpenCVConfig.cmake, and it pulls in every module. We need
# four, so find them directly and expose one INTERFACE target.
find_path(PATCHSKIN_OPENCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
add_library(patchskin_opencv INTERFACE)
target_include_directories(patchskin_opencv SYSTEM INTERFACE ${PATCHSKIN_OPENCV_INCLUDE_DIR})
foreach(module core imgproc imgcodecs videoio)
  find_library(PATCHSKIN_OPENCV_${module}_LIBRARY opencv_${module} REQUIRED)
  target_link_libraries(patchskin_opencv INTERFACE ${PATCHSKIN_OPENCV_${module}_LIBRARY})
endforeach()
