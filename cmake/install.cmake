# `cmake --install BUILD [--prefix P]`: the libraries (static), their headers, the `saltus`
# program, the bundled models and chart script, and a CMake package, so that a user's project
# builds against Saltus with
#   find_package(saltus REQUIRED)
#   target_link_libraries(app saltus::saltus)
# (examples/find_package; tests/CMakeLists.txt builds it against an installed tree).
#
# Layout under the prefix:
#   include/saltus/<folder>/*.hpp     headers, included as in the source tree: "dynamics/rnea.hpp"
#   include/saltus/saltus/saltus.hpp  the library API (saltus::api), "saltus/saltus.hpp"
#   lib/libsaltus_*.a                 saltus::dynamics, scene, contact, timestepper, collocation,
#                                     verify, render, api (saltus::saltus: all of them)
#   lib/cmake/saltus/                 saltusConfig.cmake, saltusConfigVersion.cmake, saltusTargets.cmake
#   bin/saltus                        the command line
#   share/saltus/models, scripts      built-in models, scenes and problems; the chart script
include(CMakePackageConfigHelpers)

set(SALTUS_EXPORTED_LIBRARIES dynamics scene contact timestepper collocation verify render)
set(SALTUS_INSTALL_INCLUDE_DIR ${CMAKE_INSTALL_INCLUDEDIR}/saltus)
foreach(name ${SALTUS_EXPORTED_LIBRARIES})
  set_target_properties(saltus_${name} PROPERTIES EXPORT_NAME ${name})
  target_include_directories(saltus_${name} INTERFACE $<INSTALL_INTERFACE:${SALTUS_INSTALL_INCLUDE_DIR}>)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${name}/ DESTINATION ${SALTUS_INSTALL_INCLUDE_DIR}/${name}
          FILES_MATCHING PATTERN "*.hpp")
endforeach()
# The library API: target saltus_api, headers in saltus/ (without the generated build paths).
set_target_properties(saltus_api PROPERTIES EXPORT_NAME api)
target_include_directories(saltus_api INTERFACE $<INSTALL_INTERFACE:${SALTUS_INSTALL_INCLUDE_DIR}>)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/saltus/ DESTINATION ${SALTUS_INSTALL_INCLUDE_DIR}/saltus
        FILES_MATCHING PATTERN "*.hpp")
list(TRANSFORM SALTUS_EXPORTED_LIBRARIES PREPEND saltus_ OUTPUT_VARIABLE SALTUS_EXPORTED_TARGETS)
list(APPEND SALTUS_EXPORTED_TARGETS saltus_api)

# saltus::saltus: every library, C++20, and the instruction set the libraries were built for
# (Eigen's vector alignment follows it: code built with other flags would disagree on the layout
# of fixed-size Eigen members).
add_library(saltus_all INTERFACE)
set_target_properties(saltus_all PROPERTIES EXPORT_NAME saltus)
target_link_libraries(saltus_all INTERFACE ${SALTUS_EXPORTED_TARGETS})
target_compile_features(saltus_all INTERFACE cxx_std_20)
if(SALTUS_NATIVE AND NOT SALTUS_SANITIZE)
  target_compile_options(saltus_all INTERFACE -march=native)
endif()

# MuJoCo, which saltus::verify links, by its header and library paths (verify/CMakeLists.txt).
set_target_properties(saltus_mujoco PROPERTIES EXPORT_NAME mujoco)
install(TARGETS ${SALTUS_EXPORTED_TARGETS} saltus_all saltus_mujoco EXPORT saltusTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS saltus RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(EXPORT saltusTargets NAMESPACE saltus:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/saltus)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/saltusConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/saltusConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/saltus)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/saltusConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/saltusConfig.cmake ${PROJECT_BINARY_DIR}/saltusConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/saltus)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/models DESTINATION ${CMAKE_INSTALL_DATADIR}/saltus)
install(FILES ${PROJECT_SOURCE_DIR}/scripts/charts.py DESTINATION ${CMAKE_INSTALL_DATADIR}/saltus/scripts)
