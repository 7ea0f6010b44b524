# posed's Debian package (tools/package): CPack's DEB generator over this build's own install
# rules, in a build configured with -DPOSED_PACKAGE_DEB=ON -DCMAKE_INSTALL_PREFIX=/usr.
#
# Why CPack rather than a debian/ directory and dpkg-buildpackage: lintian's verdict is the same.
# Measured on this install tree packaged both ways (debhelper 13.11.4, dh_installsystemd
# --no-enable --no-start), both get the same two warnings and no error; debhelper's dh_strip
# also drops the .comment sections (two notes fewer). Its defaults fit this package worse:
# dh_compress gzips the README that the unit's Documentation= names, and dh_installsystemd's
# preinst stops posed on every upgrade and, with --no-start, never starts it again (a robot's
# pose stream gone after apt upgrade). And a debian/ tree restates the install layout CMake
# already has, where CPack packs exactly what `cmake --install` installs: the package and a
# developer's install cannot drift apart. The packaging is this file and packaging/deb/;
# tools/package runs lintian and fails on any error.

option(POSED_PACKAGE_DEB "Lay out the install as posed's Debian package (tools/package)" OFF)
if(NOT POSED_PACKAGE_DEB)
  return()
endif()

if(NOT CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  message(FATAL_ERROR "POSED_PACKAGE_DEB: CMAKE_INSTALL_PREFIX is '${CMAKE_INSTALL_PREFIX}', the "
                      "package needs /usr (the unit runs /usr/bin/posed, and GNUInstallDirs puts "
                      "the configuration in /etc only for /usr)")
endif()
include(GNUInstallDirs)

# Debian 12's packages (systemd's own, and what its debhelper builds) list units and udev rules
# under /lib: the /usr merge moved the directories, not the paths in dpkg's file lists. sysusers.d
# and tmpfiles.d were always in /usr. systemd/CMakeLists.txt installs to these.
set(POSED_SYSTEMD_UNIT_DIR "/lib/systemd/system" CACHE STRING "where posed.service is installed" FORCE)
set(POSED_UDEV_RULES_DIR "/lib/udev/rules.d" CACHE STRING "where the udev rules are installed" FORCE)

set(posed_deb_dir ${PROJECT_SOURCE_DIR}/packaging/deb)
set(CPACK_DEBIAN_PACKAGE_RELEASE 1)  # the Debian revision: raise it for a repackaging of one version

# The Debian changelog names the version it describes; a new version needs its entry first.
file(STRINGS ${posed_deb_dir}/changelog posed_deb_changelog_head LIMIT_COUNT 1)
set(posed_deb_version "${PROJECT_VERSION}-${CPACK_DEBIAN_PACKAGE_RELEASE}")
if(NOT posed_deb_changelog_head MATCHES "^posed \\(${posed_deb_version}\\) ")
  message(FATAL_ERROR "packaging/deb/changelog:1: '${posed_deb_changelog_head}' is not an entry "
                      "for posed ${posed_deb_version}: add one (dch -v ${posed_deb_version})")
endif()
# lintian wants the changelog as changelog.Debian.gz, compressed with gzip -9 and without a name
# or time stamp (-n), so its bytes depend on the text alone.
execute_process(COMMAND gzip -9nc ${posed_deb_dir}/changelog
                OUTPUT_FILE ${PROJECT_BINARY_DIR}/changelog.Debian.gz
                RESULT_VARIABLE posed_deb_gzip_result)
if(NOT posed_deb_gzip_result EQUAL 0)
  message(FATAL_ERROR "gzip -9nc ${posed_deb_dir}/changelog failed: ${posed_deb_gzip_result}")
endif()
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${posed_deb_dir}/changelog)
install(FILES ${posed_deb_dir}/copyright ${PROJECT_BINARY_DIR}/changelog.Debian.gz
        DESTINATION ${CMAKE_INSTALL_DOCDIR})

# lintian asks a manual page of every command. help2man makes each from the binary's --help
# (posectl has no --version, so the version is given), compressed as the changelog is.
find_program(POSED_HELP2MAN help2man)
if(NOT POSED_HELP2MAN)
  message(FATAL_ERROR "POSED_PACKAGE_DEB: help2man not found, which makes the manual pages "
                      "(apt-get install help2man; tools/package installs it)")
endif()
set(posed_man_name_posed "real-time driver-to-pose daemon (lidar, cameras, IMU to poses over DDS)")
set(posed_man_name_posectl "companion tool of posed: echo, record, replay, inspect, evaluate")
foreach(command posed posectl)
  set(page ${PROJECT_BINARY_DIR}/man/${command}.1)
  add_custom_command(
    OUTPUT ${page}.gz
    COMMAND ${POSED_HELP2MAN} --no-info --no-discard-stderr --version-string=${PROJECT_VERSION}
            --name=${posed_man_name_${command}} --output=${page} $<TARGET_FILE:${command}>
    COMMAND gzip -9nf ${page}
    DEPENDS ${command}
    COMMENT "Manual page ${command}.1 from ${command} --help"
    VERBATIM)
  list(APPEND posed_man_pages ${page}.gz)
endforeach()
add_custom_target(posed_man_pages ALL DEPENDS ${posed_man_pages})
install(FILES ${posed_man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME posed)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # posed_VERSION-RELEASE_ARCH.deb
set(POSED_DEB_MAINTAINER "Seed da581f25 maintainers <maintainers@users.noreply.h-seed-da581f25.example>"
    CACHE STRING "the package's Maintainer field (whoever answers for this build of it)")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${POSED_DEB_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "real-time driver-to-pose daemon for ground robots")
set(CPACK_PACKAGE_DESCRIPTION
    "posed reads a robot's lidar (Velodyne VLP-32C), IMU (Handsfree A9), RGB-D\n"
    "(RealSense D435i) and thermal cameras, puts every sample on one host clock,\n"
    "fuses them in a lidar-inertial estimator with a visual-thermal front end and\n"
    "publishes the pose over DDS with ROS 2's message types. It records and\n"
    "replays the sensors' raw bytes. posectl echoes, records, replays, inspects,\n"
    "imports and evaluates.\n"
    ".\n"
    "The package installs a hardened systemd unit, the posed system user and udev\n"
    "rules for the sensors, and enables nothing: edit /etc/posed/posed.yaml, then\n"
    "systemctl enable --now posed.")
string(REPLACE ";" "" CPACK_PACKAGE_DESCRIPTION "${CPACK_PACKAGE_DESCRIPTION}")

# Depends: the shared libraries' packages from dpkg-shlibdeps, and adduser for postinst's
# fallback where systemd-sysusers is missing. tools/plot-eval (posectl eval --plot) is Python
# with matplotlib; plotting is optional, so it is only suggested.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "adduser")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "python3, python3-matplotlib")

set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${posed_deb_dir}/conffiles ${posed_deb_dir}/postinst ${posed_deb_dir}/prerm
    ${posed_deb_dir}/postrm)
# 0755 for the scripts and 0644 for conffiles whatever the checkout's modes are.
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)

# What lintian checks and debhelper would have done: stripped binaries, directories 0755 whatever
# the packager's umask, xz like Debian's own packages.
set(CPACK_STRIP_FILES TRUE)
set(CPACK_INSTALL_DEFAULT_DIRECTORY_PERMISSIONS
    OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
set(CPACK_DEBIAN_COMPRESSION_TYPE xz)

include(CPack)
