# Finds LCM as Debian packages it (liblcm-dev, liblcm-bin, liblcm-java 1.3.1), which has no CMake
# package of its own. lcm.pc needs glib's .pc files that liblcm-dev does not pull, so the header
# and library are found directly; the C++ API never includes glib.
#
# Defines:
#   LCM::lcm                 imported library (headers lcm/lcm-cpp.hpp, liblcm.so)
#   LCM_GEN_EXECUTABLE       lcm-gen
#   LCM_JAR                  lcm.jar (empty when liblcm-java is missing)
#   LCM_LOGGER_EXECUTABLE    lcm-logger
#   LCM_LOGPLAYER_EXECUTABLE lcm-logplayer

find_path(LCM_INCLUDE_DIR lcm/lcm-cpp.hpp)
find_library(LCM_LIBRARY NAMES lcm)
find_program(LCM_GEN_EXECUTABLE lcm-gen)
find_program(LCM_LOGGER_EXECUTABLE lcm-logger)
find_program(LCM_LOGPLAYER_EXECUTABLE lcm-logplayer)
find_file(LCM_JAR lcm.jar PATHS /usr/share/java /usr/local/share/java)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(LCM
  REQUIRED_VARS LCM_LIBRARY LCM_INCLUDE_DIR LCM_GEN_EXECUTABLE
  FAIL_MESSAGE "LCM not found: run scripts/bootstrap.sh (apt-get install liblcm-dev liblcm-bin)")

if(LCM_FOUND AND NOT TARGET LCM::lcm)
  add_library(LCM::lcm UNKNOWN IMPORTED)
  set_target_properties(LCM::lcm PROPERTIES
    IMPORTED_LOCATION "${LCM_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${LCM_INCLUDE_DIR}")
endif()
mark_as_advanced(LCM_INCLUDE_DIR LCM_LIBRARY LCM_GEN_EXECUTABLE LCM_JAR LCM_LOGGER_EXECUTABLE
                 LCM_LOGPLAYER_EXECUTABLE)
