# OpenVDB (Debian libopenvdb-dev) meshes the generated body. Debian's FindOpenVDB.cmake
# (in the multiarch library folder) also wants boost_iostreams and turns
# BUILD_SHARED_LIBS on, so the library is found directly: its headers need Boost's
# (libboost-dev) and it links TBB (libtbb-dev).
find_path(PATCHSKIN_OPENVDB_INCLUDE_DIR openvdb/openvdb.h REQUIRED)
find_path(PATCHSKIN_BOOST_INCLUDE_DIR boost/version.hpp REQUIRED)
find_library(PATCHSKIN_OPENVDB_LIBRARY openvdb REQUIRED)
find_library(PATCHSKIN_TBB_LIBRARY tbb REQUIRED)
# Its half-float type comes from Imath (libimath-dev, pulled in by libopenvdb-dev).
find_library(PATCHSKIN_IMATH_LIBRARY NAMES Imath-3_1 Imath REQUIRED)
# Eigen (libeigen3-dev) solves the bone-heat weights' sparse system.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
add_library(patchskin_body_deps INTERFACE)
target_include_directories(patchskin_body_deps SYSTEM INTERFACE ${PATCHSKIN_OPENVDB_INCLUDE_DIR}
                           ${PATCHSKIN_BOOST_INCLUDE_DIR})
target_link_libraries(patchskin_body_deps INTERFACE ${PATCHSKIN_OPENVDB_LIBRARY} ${PATCHSKIN_TBB_LIBRARY}
                      ${PATCHSKIN_IMATH_LIBRARY}
                      Eigen3::Eigen)
