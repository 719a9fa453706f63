# `cmake --install`: the static libraries, their headers under
# include/sylva/<library>/, the `sylva` command (and sylva-graphics in
# libexec/sylva), the bundled data under share/sylva, and a CMake package:
#   find_package(Sylva CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE Sylva::plant)
# with Sylva::core, ::lsys, ::turtle, ::mesh, ::plant, ::particles,
# ::terrain and ::render (when built), each bringing its dependencies.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(_sylva_libs core lsys mesh turtle plant particles terrain draw scene)
if(SYLVA_BUILD_RENDER)
  list(APPEND _sylva_libs render)
endif()
set(_sylva_targets sylva_warnings)
foreach(lib IN LISTS _sylva_libs)
  set_target_properties(sylva_${lib} PROPERTIES EXPORT_NAME ${lib})
  list(APPEND _sylva_targets sylva_${lib})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/src/${lib}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/sylva/${lib}
    FILES_MATCHING PATTERN "*.h" PATTERN "*.inl")
endforeach()
set_target_properties(sylva_warnings PROPERTIES EXPORT_NAME warnings)
install(TARGETS ${_sylva_targets} EXPORT SylvaTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/sylva)
install(EXPORT SylvaTargets NAMESPACE Sylva:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Sylva)

install(TARGETS sylva RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET sylva-graphics)
  install(TARGETS sylva-graphics RUNTIME DESTINATION ${CMAKE_INSTALL_LIBEXECDIR}/sylva)
endif()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/grammars ${PROJECT_SOURCE_DIR}/shaders
  DESTINATION ${CMAKE_INSTALL_DATADIR}/sylva)
# The example scenes: `sylva view` with no file opens one; their grammar
# paths (../../grammars) lead to share/sylva/grammars from there.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/scenes
  DESTINATION ${CMAKE_INSTALL_DATADIR}/sylva/examples)

set(SYLVA_PACKAGE_RENDER ${SYLVA_BUILD_RENDER})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/SylvaConfig.cmake.in
  ${PROJECT_BINARY_DIR}/SylvaConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Sylva)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/SylvaConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/SylvaConfig.cmake ${PROJECT_BINARY_DIR}/SylvaConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Sylva)
