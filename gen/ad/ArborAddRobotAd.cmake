# arbor_add_robot_ad(<target> ROBOT <robot-target> STRUCT <qualified struct>
#                    ROBOT_HEADER <robots/name.hpp> HEADER <name_ad.hpp> [HESSIANS])
#
# Generated straight-line derivatives of a robot (gen/ad, arbor-adgen): builds a small host
# program that traces the robot's aba, rnea and frame kinematics with a symbolic scalar,
# differentiates the graph (forward or reverse mode, whichever is cheaper per function) and
# writes the header <robots/HEADER> with GeneratedCode specialisations: Jacobians of
# ForwardDynamics, InverseDynamics and every FramePosition; with HESSIANS also
# <robots/HEADER minus .hpp>_hessian.hpp with GeneratedHessian specialisations, the Hessians of
# lambda^T FD and lambda^T ID (a header of its own: a unit that needs only Jacobians does not
# parse them). Creates the INTERFACE library <target> carrying it (it links
# ROBOT). Select the code with the provider tag arbor::ad::Generated. Native builds only: the
# program runs at build time.
include_guard(GLOBAL)
set(_ARBOR_ADGEN_DIR ${CMAKE_CURRENT_LIST_DIR})

function(arbor_add_robot_ad target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "HESSIANS" "ROBOT;STRUCT;ROBOT_HEADER;HEADER" "")
  if(ARG_UNPARSED_ARGUMENTS OR NOT ARG_ROBOT OR NOT ARG_STRUCT OR NOT ARG_ROBOT_HEADER
     OR NOT ARG_HEADER)
    message(FATAL_ERROR "arbor_add_robot_ad(${target} ROBOT <t> STRUCT <s> ROBOT_HEADER <h> "
                        "HEADER <h> [HESSIANS])")
  endif()
  set(robot_struct ${ARG_STRUCT})
  set(robot_header ${ARG_ROBOT_HEADER})
  set(src ${CMAKE_CURRENT_BINARY_DIR}/${target}_adgen.cpp)
  configure_file(${_ARBOR_ADGEN_DIR}/adgen_robot.cpp.in ${src} @ONLY)
  add_executable(${target}_adgen EXCLUDE_FROM_ALL ${src})
  target_include_directories(${target}_adgen PRIVATE ${_ARBOR_ADGEN_DIR})
  target_link_libraries(${target}_adgen PRIVATE ${ARG_ROBOT})
  # A host tool run once per build: optimised a little, compiled fast.
  target_compile_options(${target}_adgen PRIVATE -O1)
  set(dir ${CMAKE_CURRENT_BINARY_DIR}/${target}_gen)
  set(out ${dir}/robots/${ARG_HEADER})
  set(outputs ${out})
  if(ARG_HESSIANS)
    string(REGEX REPLACE "\\.hpp$" "_hessian.hpp" hout "${out}")
    list(APPEND outputs ${hout})
  endif()
  add_custom_command(
    OUTPUT ${outputs}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}/robots
    COMMAND ${target}_adgen ${outputs}
    DEPENDS ${target}_adgen
    COMMENT "arbor-adgen: ${ARG_STRUCT} -> robots/${ARG_HEADER}"
    VERBATIM)
  add_custom_target(${target}_generate DEPENDS ${outputs})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_generate)
  target_include_directories(${target} INTERFACE $<BUILD_INTERFACE:${dir}>)
  target_link_libraries(${target} INTERFACE ${ARG_ROBOT})
endfunction()
