# What `cmake --install` puts under the prefix, and the Debian package CPack makes of it (README "Install"):
#
#   bin/selfcal, bin/selfcal-full, bin/selfcal-robot-sim
#   lib/selfcal/libselfcal_camera_formats.so   (SELFCAL_INSTALL_LIBDIR: loaded by selfcal, not linked)
#   share/selfcal/config/                      (SELFCAL_INSTALL_DATADIR: the shipped robots and trajectories)
#   share/selfcal/plotly.min.js                (the minified copy report.html inlines, when the build made it)
#   share/doc/selfcal/                         (README, LICENSE, docs/)
#
# The programs find all of it from their own location (modules/base/install_layout.h); the relative paths
# are fixed at configure time, so `cmake --install --prefix P` and the package's /usr give the same layout.
install(TARGETS selfcal selfcal-full selfcal-robot-sim RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS selfcal_camera_formats LIBRARY DESTINATION ${SELFCAL_INSTALL_LIBDIR})
install(DIRECTORY config DESTINATION ${SELFCAL_INSTALL_DATADIR})
set(SELFCAL_BUNDLES_PLOTLY OFF)
if(TARGET selfcal_plotly_min)
  install(FILES ${SELFCAL_PLOTLY_JS_PATH} DESTINATION ${SELFCAL_INSTALL_DATADIR})
  set(SELFCAL_BUNDLES_PLOTLY ON)
endif()
install(FILES README.md LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY docs DESTINATION ${CMAKE_INSTALL_DOCDIR})
# The line protocol's reference server, the file a real arm's server starts from (docs/robot-protocol.md).
install(PROGRAMS scripts/reference-robot-server DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)
install(DIRECTORY scripts/robot-side DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)

# The Debian package: `cpack --config build/release/CPackConfig.cmake` (or `cpack` in the build directory).
# Its dependencies are those of the libraries the programs link, found by dpkg-shlibdeps.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME selfcal)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Self-calibration of a camera-equipped robot arm")
set(CPACK_PACKAGE_DESCRIPTION "selfcal calibrates the kinematics, the hand-eye transform and the camera of a robot arm\
 from images of an unknown scene (Meng & Zhuang), plans and runs the measurement poses, and writes the\
 calibrated model, a URDF and an HTML report.")
set(CPACK_RESOURCE_FILE_LICENSE "${CMAKE_SOURCE_DIR}/LICENSE")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(SELFCAL_PACKAGE_MAINTAINER "selfcal maintainers <selfcal@invalid>" CACHE STRING
  "Maintainer field of the Debian package")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${SELFCAL_PACKAGE_MAINTAINER}")
if(NOT SELFCAL_BUNDLES_PLOTLY)
  # report.html then inlines Debian's copy (/usr/share/python3-plotly/plotly.js).
  set(CPACK_DEBIAN_PACKAGE_RECOMMENDS python3-plotly)
endif()
include(CPack)

# The install and the package, run with the source and build trees out of reach.
if(SELFCAL_BUILD_TESTS)
  foreach(mode prefix deb)
    if(mode STREQUAL prefix)
      set(name Install.PrefixRunsWithoutTheSourceTree)
    else()
      set(name Install.DebianPackageRunsWithoutTheSourceTree)
    endif()
    add_test(NAME ${name} COMMAND bash ${CMAKE_SOURCE_DIR}/test/integration/install_test.sh ${mode}
      ${CMAKE_BINARY_DIR} ${CMAKE_SOURCE_DIR})
    set_tests_properties(${name} PROPERTIES LABELS "integration;install" SKIP_RETURN_CODE 77 TIMEOUT 300)
  endforeach()
endif()
