# Installing vrmlray (cmake --install) and its Debian package (cpack -G DEB): the binary, the OpenImageIO
# and OpenEXR modules in lib/vrmlray/ (where src/image/module_path.h looks), the man page generated from
# docs/manual.md, and the bash completion.
include(GNUInstallDirs)
install(TARGETS vrmlray RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS vrmlray_oiio vrmlray_exr LIBRARY DESTINATION lib/vrmlray)
if(VRMLRAY_MPI)
    install(TARGETS vrmlray_mpi LIBRARY DESTINATION lib/vrmlray)
endif()
install(FILES ${CMAKE_SOURCE_DIR}/tools/completion/vrmlray.bash
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME vrmlray)

find_program(GO_MD2MAN go-md2man)
if(GO_MD2MAN)
    set(MAN_PAGE ${CMAKE_BINARY_DIR}/vrmlray.1)
    add_custom_command(OUTPUT ${MAN_PAGE}
        COMMAND ${CMAKE_SOURCE_DIR}/tools/make_man.sh ${CMAKE_SOURCE_DIR}/docs/manual.md ${PROJECT_VERSION} ${MAN_PAGE}
        DEPENDS ${CMAKE_SOURCE_DIR}/docs/manual.md ${CMAKE_SOURCE_DIR}/tools/make_man.sh
        COMMENT "Man page from docs/manual.md")
    add_custom_target(man ALL DEPENDS ${MAN_PAGE})
    install(FILES ${MAN_PAGE} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
else()
    message(STATUS "go-md2man not found: no man page (tools/setup.sh installs it)")
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME vrmlray)
set(CPACK_PACKAGE_CONTACT "vrmlray developers")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "fast, exact ray tracer for VRML97 and X3D scene files")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
# The shared libraries the binary and the module link decide the package's dependencies (dpkg-shlibdeps).
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# libxml2 is loaded with dlopen, so shlibdeps cannot see it.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libxml2")
# The Python module (python/CMakeLists.txt installs it) imports numpy at run time, which shlibdeps
# cannot see either.
if(VRMLRAY_PYTHON)
    set(CPACK_DEBIAN_PACKAGE_DEPENDS "libxml2, python3, python3-numpy")
endif()
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
include(CPack)
