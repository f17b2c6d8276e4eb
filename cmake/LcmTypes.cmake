# sg_lcm_types(TARGET <name> JAR <jar-name> FILES <a.lcm> ...)
#
# Generates C++ headers (and, when a JDK and lcm.jar are present, a jar) from .lcm files with
# lcm-gen. One custom command per .lcm file, so only a changed file is regenerated. The output
# names come from each file's `package` and `struct` lines. Creates:
#   <TARGET>      INTERFACE library: link it to include <package/type.hpp>
#   <JAR>         the jar of the same types, file <TARGET>.jar (lcm-spy finds them on CLASSPATH by fingerprint);
#                 its path is in the target property JAR_FILE.
function(sg_lcm_types)
  cmake_parse_arguments(ARG "" "TARGET;JAR" "FILES" ${ARGN})
  set(cpp_dir ${CMAKE_CURRENT_BINARY_DIR}/cpp)
  set(java_dir ${CMAKE_CURRENT_BINARY_DIR}/java)
  set(all_hpp)
  set(all_java)
  foreach(lcm_file IN LISTS ARG_FILES)
    get_filename_component(lcm_abs ${lcm_file} ABSOLUTE)
    file(STRINGS ${lcm_abs} package_line REGEX "^[ \t]*package[ \t]+[A-Za-z0-9_.]+[ \t]*;")
    file(STRINGS ${lcm_abs} struct_lines REGEX "^[ \t]*struct[ \t]+[A-Za-z0-9_]+")
    if(NOT package_line OR NOT struct_lines)
      message(FATAL_ERROR "${lcm_file}: needs a 'package' line and at least one 'struct'")
    endif()
    string(REGEX REPLACE "^[ \t]*package[ \t]+([A-Za-z0-9_.]+).*" "\\1" package "${package_line}")
    string(REPLACE "." "/" package_path "${package}")
    set(hpp)
    set(java)
    foreach(line IN LISTS struct_lines)
      string(REGEX REPLACE "^[ \t]*struct[ \t]+([A-Za-z0-9_]+).*" "\\1" type "${line}")
      list(APPEND hpp ${cpp_dir}/${package_path}/${type}.hpp)
      list(APPEND java ${java_dir}/${package_path}/${type}.java)
    endforeach()
    add_custom_command(
      OUTPUT ${hpp}
      COMMAND ${LCM_GEN_EXECUTABLE} -x --cpp-hpath ${cpp_dir} --cpp-std c++11 ${lcm_abs}
      DEPENDS ${lcm_abs}
      COMMENT "lcm-gen (C++) ${lcm_file}"
      VERBATIM)
    list(APPEND all_hpp ${hpp})
    if(Java_FOUND AND LCM_JAR)
      add_custom_command(
        OUTPUT ${java}
        COMMAND ${LCM_GEN_EXECUTABLE} -j --jpath ${java_dir} ${lcm_abs}
        DEPENDS ${lcm_abs}
        COMMENT "lcm-gen (Java) ${lcm_file}"
        VERBATIM)
      list(APPEND all_java ${java})
    endif()
  endforeach()

  add_custom_target(${ARG_TARGET}_generate DEPENDS ${all_hpp})
  add_library(${ARG_TARGET} INTERFACE)
  add_dependencies(${ARG_TARGET} ${ARG_TARGET}_generate)
  # SYSTEM: lcm-gen's code is not ours to keep warning-free.
  target_include_directories(${ARG_TARGET} SYSTEM INTERFACE ${cpp_dir})
  target_link_libraries(${ARG_TARGET} INTERFACE LCM::lcm)

  if(all_java)
    add_jar(${ARG_JAR} SOURCES ${all_java} INCLUDE_JARS ${LCM_JAR} OUTPUT_NAME ${ARG_TARGET})
  else()
    message(STATUS "No JDK or lcm.jar: the ${ARG_JAR} jar for lcm-spy is not built")
  endif()
endfunction()
