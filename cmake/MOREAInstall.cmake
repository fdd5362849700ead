# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
# `cmake --install`: headers, the static libraries, the `morea` command and a
# CMake package (find_package(MultiObjectiveRegistration)). The Python
# package installs only when pip builds it (wrapping/python).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(MOREA_INSTALL_INCLUDE_DIR ${CMAKE_INSTALL_INCLUDEDIR}/MultiObjectiveRegistration)
set(MOREA_INSTALL_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/MultiObjectiveRegistration)
string(REPLACE ";" " " MOREA_ITK_COMPONENTS_TEXT "${MOREA_ITK_COMPONENTS}")

install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/ DESTINATION ${MOREA_INSTALL_INCLUDE_DIR}
        FILES_MATCHING PATTERN "*.h" PATTERN "*.hxx")
install(TARGETS MOREACore MOREAMesh MOREACuda MultiObjectiveRegistration
        EXPORT MultiObjectiveRegistrationTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${MOREA_INSTALL_INCLUDE_DIR})
install(TARGETS morea RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(EXPORT MultiObjectiveRegistrationTargets NAMESPACE MultiObjectiveRegistration::
        DESTINATION ${MOREA_INSTALL_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/MultiObjectiveRegistrationConfig.cmake.in
  ${PROJECT_BINARY_DIR}/MultiObjectiveRegistrationConfig.cmake
  INSTALL_DESTINATION ${MOREA_INSTALL_CMAKE_DIR}
  PATH_VARS MOREA_INSTALL_INCLUDE_DIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/MultiObjectiveRegistrationConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/MultiObjectiveRegistrationConfig.cmake
              ${PROJECT_BINARY_DIR}/MultiObjectiveRegistrationConfigVersion.cmake
        DESTINATION ${MOREA_INSTALL_CMAKE_DIR})
