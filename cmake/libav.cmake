# FFmpeg's libraries (Debian: libavcodec-dev libavformat-dev libavutil-dev
# libswscale-dev) for the H.264 preview with a real-time x264 preset, which
# OpenCV's VideoWriter cannot set. One INTERFACE target; used only in
# render/output/internal/h264_encoder.cpp.
find_package(PkgConfig REQUIRED)
pkg_check_modules(PATCHSKIN_LIBAV REQUIRED IMPORTED_TARGET libavcodec libavformat libavutil libswscale)
add_library(patchskin_libav INTERFACE)
target_link_libraries(patchskin_libav INTERFACE PkgConfig::PATCHSKIN_LIBAV)
