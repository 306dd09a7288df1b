# Installation (docs/install.md): the headers under include/atmos/, libatmos.so.0.2 and
# libatmos.a, the CLI, its man pages, the docs, a pkg-config file (atmos.pc) and a CMake
# package (find_package(atmos) -> atmos::atmos, atmos::atmos_static).
include(CMakePackageConfigHelpers)

set(ATMOS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/atmos)
install(TARGETS atmos_shared atmos_static EXPORT atmosTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS atmos RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The modules opened at run time (src/core/module.h), beside the library.
foreach(_m atmos_openvdb atmos_gdal)
  if(TARGET ${_m})
    install(TARGETS ${_m} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  endif()
endforeach()
install(DIRECTORY include/atmos DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT atmosTargets NAMESPACE atmos:: DESTINATION ${ATMOS_CMAKE_DIR})
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/atmos-config.cmake.in
                              ${CMAKE_BINARY_DIR}/atmos-config.cmake INSTALL_DESTINATION ${ATMOS_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/atmos-config-version.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/atmos-config.cmake ${CMAKE_BINARY_DIR}/atmos-config-version.cmake
        DESTINATION ${ATMOS_CMAKE_DIR})

# pkg-config: what a static link needs beyond libatmos.a, by the build's options.
set(ATMOS_PC_REQUIRES_PRIVATE "libpng libcjson libjpeg OpenEXR tinyobjloader fftw3f")
set(ATMOS_PC_LIBS_PRIVATE "-fopenmp -lm")
if(ATMOS_HAVE_NETCDF)
  string(APPEND ATMOS_PC_REQUIRES_PRIVATE " netcdf")
endif()
# The OpenVDB and GDAL readers are modules beside the library, opened when a .vdb or a height
# map file is read (src/core/module.h): a static link needs neither, only dlopen.
if(CMAKE_DL_LIBS)
  string(APPEND ATMOS_PC_LIBS_PRIVATE " -l${CMAKE_DL_LIBS}")
endif()
# the C++ runtime of the OBJ reader's shim (src/mesh/mesh_obj.cpp)
string(APPEND ATMOS_PC_LIBS_PRIVATE " -lstdc++")
# The prefix is found from the file's own place, so the package can be installed anywhere
# (cmake --install --prefix, DESTDIR) and moved.
file(RELATIVE_PATH ATMOS_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
configure_file(${CMAKE_SOURCE_DIR}/cmake/atmos.pc.in ${CMAKE_BINARY_DIR}/atmos.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/atmos.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
# The build tree's (absolute paths, not installed): PKG_CONFIG_PATH=build finds it before
# atmos.pc, whose paths are the installed prefix's.
configure_file(${CMAKE_SOURCE_DIR}/cmake/atmos-uninstalled.pc.in ${CMAKE_BINARY_DIR}/atmos-uninstalled.pc @ONLY)

# Man pages from the CLI's own help text (scripts/make-man.sh, with Debian's help2man).
add_custom_command(OUTPUT ${CMAKE_BINARY_DIR}/man/atmos.1
                   COMMAND sh ${CMAKE_SOURCE_DIR}/scripts/make-man.sh $<TARGET_FILE:atmos>
                           ${CMAKE_BINARY_DIR}/man ${PROJECT_VERSION}
                   DEPENDS atmos ${CMAKE_SOURCE_DIR}/scripts/make-man.sh
                   COMMENT "Man pages from 'atmos --help'")
add_custom_target(atmos_man ALL DEPENDS ${CMAKE_BINARY_DIR}/man/atmos.1)
install(DIRECTORY ${CMAKE_BINARY_DIR}/man/ DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 FILES_MATCHING PATTERN "*.1")
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
