# arbor_add_robot(<target> URDF <file>
#                 [NAME <StructName>] [NAMESPACE <ns>] [HEADER <file.hpp>]
#                 [ROOT <link>] [TIP <link>...] [LOCK <joint>=<value>...]
#                 [LOCK_MIMIC] [SNAP <tol>] [FIX_INERTIA | STRICT_INERTIA])
#
# Runs arbor-gen at build time (again whenever the URDF or the generator changes) and creates an
# INTERFACE library <target> that carries the generated header. Link it and include it as
#   #include <robots/<HEADER>>        (HEADER defaults to <target>.hpp)
# The generator is the arbor-gen target of this build, the imported arbor::arbor-gen of an
# installed package, or the executable named by the cache variable ARBOR_GEN_EXECUTABLE (for
# cross builds, where the generator must run on the build machine).
#
# In a source tree (add_subdirectory(arbor)) the generated derivatives and stage code come with it:
# arbor_add_robot_ad (gen/ad/ArborAddRobotAd.cmake) and arbor_add_stage_ad (a problem's
# Gauss-Newton stages as straight-line code, gen/ad/ArborAddStageAd.cmake; docs/tutorial.md,
# "The fast configuration").
include_guard(GLOBAL)
if(EXISTS "${CMAKE_CURRENT_LIST_DIR}/../ad/ArborAddStageAd.cmake")
  include("${CMAKE_CURRENT_LIST_DIR}/../ad/ArborAddRobotAd.cmake")
  include("${CMAKE_CURRENT_LIST_DIR}/../ad/ArborAddStageAd.cmake")
endif()

function(arbor_add_robot target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "LOCK_MIMIC;FIX_INERTIA;STRICT_INERTIA"
                        "URDF;NAME;NAMESPACE;HEADER;ROOT;SNAP" "TIP;LOCK")
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "arbor_add_robot(${target}): unknown arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT ARG_URDF)
    message(FATAL_ERROR "arbor_add_robot(${target}): URDF <file> is required")
  endif()
  get_filename_component(urdf "${ARG_URDF}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  if(NOT EXISTS "${urdf}")
    message(FATAL_ERROR "arbor_add_robot(${target}): URDF file not found: ${urdf}")
  endif()
  if(NOT ARG_HEADER)
    set(ARG_HEADER "${target}.hpp")
  endif()

  if(ARBOR_GEN_EXECUTABLE)
    set(gen "${ARBOR_GEN_EXECUTABLE}")
    set(gen_dep "${ARBOR_GEN_EXECUTABLE}")
  elseif(TARGET arbor::arbor-gen)
    set(gen "$<TARGET_FILE:arbor::arbor-gen>")
    set(gen_dep arbor::arbor-gen)
  else()
    message(FATAL_ERROR "arbor_add_robot(${target}): no arbor-gen: build it, find_package(arbor), "
                        "or set ARBOR_GEN_EXECUTABLE")
  endif()

  set(args "${urdf}")
  if(ARG_NAME)
    list(APPEND args --name "${ARG_NAME}")
  endif()
  if(ARG_NAMESPACE)
    list(APPEND args --namespace "${ARG_NAMESPACE}")
  endif()
  if(ARG_ROOT)
    list(APPEND args --root "${ARG_ROOT}")
  endif()
  foreach(tip IN LISTS ARG_TIP)
    list(APPEND args --tip "${tip}")
  endforeach()
  foreach(lock IN LISTS ARG_LOCK)
    list(APPEND args --lock "${lock}")
  endforeach()
  if(ARG_LOCK_MIMIC)
    list(APPEND args --lock-mimic)
  endif()
  if(ARG_SNAP)
    list(APPEND args --snap "${ARG_SNAP}")
  endif()
  if(ARG_FIX_INERTIA)
    list(APPEND args --fix-inertia)
  endif()
  if(ARG_STRICT_INERTIA)
    list(APPEND args --strict-inertia)
  endif()

  set(dir "${CMAKE_CURRENT_BINARY_DIR}/${target}_gen")
  set(out "${dir}/robots/${ARG_HEADER}")
  add_custom_command(
    OUTPUT "${out}"
    COMMAND "${gen}" ${args} -o "${out}"
    DEPENDS "${urdf}" ${gen_dep}
    COMMENT "arbor-gen: ${ARG_URDF} -> robots/${ARG_HEADER}"
    VERBATIM)
  add_custom_target(${target}_generate DEPENDS "${out}")
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_generate)
  target_include_directories(${target} INTERFACE "$<BUILD_INTERFACE:${dir}>")
  if(TARGET arbor::arbor)
    target_link_libraries(${target} INTERFACE arbor::arbor)
  endif()
  set_property(TARGET ${target} PROPERTY ARBOR_ROBOT_HEADER "${out}")
endfunction()
