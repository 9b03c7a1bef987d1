# `cmake --install` of the firmware library for drive makers: the core headers (templates),
# the HAL contract and its MCU backends' headers, the C API, the core and C API archives for
# this build's target and scalar, and a CMake package:
#   find_package(jointguard 0.2 REQUIRED)
#   target_link_libraries(app PRIVATE jointguard::core jointguard::capi jointguard::hal)
# The package records the scalar it was built with (jointguard_SCALAR: float or q; the
# exported targets define JG_SCALAR_Q accordingly) and the CPU (jointguard_MCU_CPU, empty
# for a host build). Install once per target and scalar, each into its own prefix.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(JG_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/jointguard)
install(TARGETS jg_core jg_core_headers jg_hal_headers jg_capi
        EXPORT jointguardTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/firmware/include/ ${PROJECT_SOURCE_DIR}/hal/include/
                  ${PROJECT_SOURCE_DIR}/firmware/capi/include/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT jointguardTargets NAMESPACE jointguard:: DESTINATION ${JG_INSTALL_CMAKEDIR})

if(CMAKE_CROSSCOMPILING)
  set(JG_PACKAGE_MCU_CPU ${JG_MCU_CPU})
else()
  set(JG_PACKAGE_MCU_CPU "")
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/jointguardConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/jointguardConfig.cmake
                              INSTALL_DESTINATION ${JG_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/jointguardConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/jointguardConfig.cmake ${PROJECT_BINARY_DIR}/jointguardConfigVersion.cmake
        DESTINATION ${JG_INSTALL_CMAKEDIR})
install(FILES ${PROJECT_SOURCE_DIR}/CHANGELOG.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/jointguard)
