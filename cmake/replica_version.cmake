# The program's and the package's version from git, fixed when CMake configures.
#   replica_version(SOURCE_DIR PROJECT_VERSION DESCRIBE_OVERRIDE PACKAGE_OVERRIDE)
# sets REPLICA_GIT_COMMIT ('git describe --always --dirty --abbrev=12', "unknown-commit" without
# git) and REPLICA_VERSION, the package version: the project version, then the number of commits
# and the commit (0.1.0+git1234.g5237685c1a2b, '.dirty' added for uncommitted changes), so that a
# package built from a later commit sorts higher for dpkg and apt, and installing it upgrades (the
# count orders, the hash names). Debian compares digit runs as numbers and sorts '+' after the end
# of a version, so 0.1.0 < 0.1.0+git9.g... < 0.1.0+git10.g... < 0.1.1. A shallow clone counts only
# the commits it has; a tree without git gets the project version, or PACKAGE_OVERRIDE (e.g. for a
# source tarball). tests/package/version_order.sh checks the ordering on two commits.
#
# In script mode it prints the package version of the tree SOURCE_DIR:
#   cmake -DSOURCE_DIR=DIR -DPROJECT_VERSION=0.1.0 -P cmake/replica_version.cmake
function(replica_version source_dir project_version describe_override package_override)
    find_package(Git QUIET)
    set(git_ok FALSE)
    if(GIT_FOUND AND EXISTS "${source_dir}/.git")
        set(git_ok TRUE)
    endif()
    set(describe "${describe_override}")
    if(NOT describe AND git_ok)
        execute_process(COMMAND "${GIT_EXECUTABLE}" describe --always --dirty --abbrev=12
                        WORKING_DIRECTORY "${source_dir}" OUTPUT_VARIABLE describe
                        OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE rc)
        if(NOT rc EQUAL 0)
            set(describe "")
        endif()
    endif()
    if(NOT describe)
        set(describe "unknown-commit")
    endif()
    set(version "${package_override}")
    if(NOT version AND git_ok)
        execute_process(COMMAND "${GIT_EXECUTABLE}" rev-list --count HEAD
                        WORKING_DIRECTORY "${source_dir}" OUTPUT_VARIABLE count
                        OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE count_rc)
        execute_process(COMMAND "${GIT_EXECUTABLE}" rev-parse --short=12 HEAD
                        WORKING_DIRECTORY "${source_dir}" OUTPUT_VARIABLE hash
                        OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE hash_rc)
        if(count_rc EQUAL 0 AND hash_rc EQUAL 0)
            set(version "${project_version}+git${count}.g${hash}")
            if(describe MATCHES "-dirty$")
                string(APPEND version ".dirty")
            endif()
        endif()
        # A commit or a checkout configures again, so that the next build has the new version.
        execute_process(COMMAND "${GIT_EXECUTABLE}" rev-parse --absolute-git-dir
                        WORKING_DIRECTORY "${source_dir}" OUTPUT_VARIABLE git_dir
                        OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
        if(NOT CMAKE_SCRIPT_MODE_FILE AND EXISTS "${git_dir}/logs/HEAD")
            set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${git_dir}/logs/HEAD")
        endif()
    endif()
    if(NOT version)
        set(version "${project_version}")
    endif()
    set(REPLICA_GIT_COMMIT "${describe}" PARENT_SCOPE)
    set(REPLICA_VERSION "${version}" PARENT_SCOPE)
endfunction()

if(CMAKE_SCRIPT_MODE_FILE STREQUAL CMAKE_CURRENT_LIST_FILE)
    replica_version("${SOURCE_DIR}" "${PROJECT_VERSION}" "" "")
    message("${REPLICA_VERSION}")
endif()
