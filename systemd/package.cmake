# The Debian package (`cpack -G DEB` in the build folder): the binary (stripped, hardened), its
# man page, the systemd unit, the udev rule for the cameras, the config (a conffile) and its templates, the operator page, the
# documentation with its copyright and changelog; the maintainer scripts in systemd/deb/ add the
# `boxd` system user the unit runs as and register the unit with deb-systemd-helper. Lintian
# accepts it (tests/daemon/cli/package_test.cpp runs it).

# cpack packs what was built; it does not build first (a package made while the tests run must
# not relink the binaries they run).
set(CMAKE_SKIP_INSTALL_ALL_DEPENDENCY TRUE)

# Who answers for the package: -DBOXD_PACKAGE_MAINTAINER="Name <address>", else the git identity
# of the tree the package is built from.
execute_process(COMMAND git -C ${PROJECT_SOURCE_DIR} config user.name
    OUTPUT_VARIABLE git_name OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
execute_process(COMMAND git -C ${PROJECT_SOURCE_DIR} config user.email
    OUTPUT_VARIABLE git_email OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(git_name AND git_email)
    set(maintainer_default "${git_name} <${git_email}>")
else()
    set(maintainer_default "boxd packagers <packaging@boxd.example>")
    message(WARNING "no git identity: the package's maintainer is a placeholder; "
                    "set -DBOXD_PACKAGE_MAINTAINER=\"Name <address>\"")
endif()
set(BOXD_PACKAGE_MAINTAINER "${maintainer_default}" CACHE STRING
    "the Debian package's Maintainer: Name <address>")

install(FILES systemd/boxd.service DESTINATION lib/systemd/system)
# USB access for the `boxd` user (plugdev) to the depth cameras and the Kinect's motor.
install(FILES systemd/60-boxd-depth-cameras.rules DESTINATION lib/udev/rules.d)
# Shipped 0644 as Debian policy 10.9 asks; postinst makes it root:boxd 0640 (it may come to hold
# the API's bearer token and the MQTT password).
install(FILES config/boxd.yaml DESTINATION /etc/boxd)
install(FILES config/boxd.yaml config/sim.yaml DESTINATION share/boxd/config)
install(FILES README.md DESTINATION share/doc/boxd)
# The README links the documentation beside it.
install(DIRECTORY docs/ DESTINATION share/doc/boxd/docs)
install(FILES daemon/web/index.html daemon/web/page.css daemon/web/page.js daemon/web/cloud_view.js
        DESTINATION share/boxd/web)

# copyright and changelog.gz (a native package's), as Debian policy 12.5 and 12.7 ask.
set(doc_build ${PROJECT_BINARY_DIR}/package)
execute_process(COMMAND git -C ${PROJECT_SOURCE_DIR} log -1 "--date=format:%a, %d %b %Y %H:%M:%S %z" --format=%cd
    OUTPUT_VARIABLE BOXD_PACKAGE_DATE OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(NOT BOXD_PACKAGE_DATE)
    string(TIMESTAMP BOXD_PACKAGE_DATE "%a, %d %b %Y %H:%M:%S +0000" UTC)
endif()
configure_file(systemd/deb/copyright ${doc_build}/copyright @ONLY)
configure_file(systemd/deb/changelog.in ${doc_build}/changelog @ONLY)
add_custom_command(OUTPUT ${doc_build}/changelog.gz
    COMMAND gzip -9n -c ${doc_build}/changelog > ${doc_build}/changelog.gz
    DEPENDS ${doc_build}/changelog VERBATIM)

# The man page, from the binary's own help (help2man), with every subcommand's help in it.
find_program(BOXD_HELP2MAN help2man)
set(package_files ${doc_build}/changelog.gz)
if(BOXD_HELP2MAN AND NOT BOXD_SANITIZE AND NOT BOXD_TSAN AND NOT BOXD_FUZZ)  # a product build
    add_custom_command(OUTPUT ${doc_build}/boxd.1.gz
        COMMAND ${CMAKE_COMMAND} -DBOXD=$<TARGET_FILE:boxd> -DHELP2MAN=${BOXD_HELP2MAN}
                -DOUT=${doc_build}/boxd.1 -P ${PROJECT_SOURCE_DIR}/systemd/man_page.cmake
        COMMAND gzip -9n -f ${doc_build}/boxd.1
        DEPENDS boxd ${PROJECT_SOURCE_DIR}/systemd/man_page.cmake VERBATIM)
    list(APPEND package_files ${doc_build}/boxd.1.gz)
    install(FILES ${doc_build}/boxd.1.gz DESTINATION share/man/man1)
else()
    message(STATUS "no man page in this build (a sanitizer build, or no help2man)")
endif()
add_custom_target(boxd_package_files ALL DEPENDS ${package_files})
install(FILES ${doc_build}/copyright ${doc_build}/changelog.gz DESTINATION share/doc/boxd)
install(FILES systemd/deb/lintian-overrides DESTINATION share/lintian/overrides RENAME boxd)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME boxd)
set(CPACK_PACKAGE_VENDOR boxd)
set(CPACK_PACKAGE_CONTACT "${BOXD_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${BOXD_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "parcel dimensioner with a depth camera and a turntable")
# The extended description (CPack puts the summary above it as the synopsis).
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "boxd measures parcels for logistics stations. A parcel is put on a Modbus
turntable; boxd turns it, captures and averages depth frames at each pose,
registers the views and reports the smallest enclosing cuboid, its 95%
bounds, the shape class and the volume, or refuses when its readings cannot
support a size.

It runs as a systemd service with a REST/JSON API, MQTT publishing, Prometheus
metrics and an operator page, and offers a command line to calibrate the
station, record sessions and measure them offline.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # boxd_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)   # Depends: the shared libraries boxd links
# adduser (postinst), deb-systemd-helper/-invoke (init-system-helpers), the page's three.js.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "adduser, init-system-helpers (>= 1.52), libjs-three")
set(CPACK_STRIP_FILES TRUE)  # no debug symbols shipped (a Release build has none to split)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/systemd/deb/postinst ${PROJECT_SOURCE_DIR}/systemd/deb/prerm
    ${PROJECT_SOURCE_DIR}/systemd/deb/postrm ${PROJECT_SOURCE_DIR}/systemd/deb/conffiles)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)
include(CPack)
