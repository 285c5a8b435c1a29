# arbor_add_stage_ad(<target> HEADER <name.hpp> INCLUDE <header> DEFINITIONS <qualified names...>
#                    [INCLUDE_DIRS <dirs...>] [LIBS <targets...>] [DEFINES <definitions...>])
#
# Generated Gauss-Newton stage linearisations of OCPs (arbor/ocp/generated_stage.hpp): builds a
# small host program that includes <header> (found through INCLUDE_DIRS and LIBS' include
# directories; DEFINES: compile definitions it needs, e.g. the options that choose the
# problem's expressions), traces ocp::linearize_path and ocp::linearize_terminal of each listed
# problem definition (a Workspace<T> alias and a static problem(ws)) with arbor-adgen's symbolic
# scalar (gen/ad), and writes <name.hpp> with GeneratedStage specialisations. Creates the
# INTERFACE library <target> carrying it (it links LIBS, defines DEFINES). Select the code with
# ocp::with_generated_stage<Definition>(problem). Native builds only: the program runs at build
# time; a cross build must take the header a host build generated (examples/contour/stages does,
# from ARBOR_HOST_BUILD_DIR).
include_guard(GLOBAL)
include(${CMAKE_CURRENT_LIST_DIR}/ArborAdgenProgram.cmake)

function(arbor_add_stage_ad target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "HEADER;INCLUDE"
                        "DEFINITIONS;INCLUDE_DIRS;LIBS;DEFINES")
  if(ARG_UNPARSED_ARGUMENTS OR NOT ARG_HEADER OR NOT ARG_INCLUDE OR NOT ARG_DEFINITIONS)
    message(FATAL_ERROR "arbor_add_stage_ad(${target} HEADER <h> INCLUDE <h> DEFINITIONS <d...> "
                        "[INCLUDE_DIRS <d...>] [LIBS <t...>] [DEFINES <d...>])")
  endif()
  string(REPLACE ";" ", " def_list "${ARG_DEFINITIONS}")
  _arbor_adgen_quoted(def_names ${ARG_DEFINITIONS})
  set(stage_include ${ARG_INCLUDE})
  set(src ${CMAKE_CURRENT_BINARY_DIR}/${target}_adgen.cpp)
  configure_file(${CMAKE_CURRENT_FUNCTION_LIST_DIR}/adgen_stage.cpp.in ${src} @ONLY)
  _arbor_adgen_header(${target} SOURCE ${src} HEADER ${ARG_HEADER}
                      COMMENT "arbor-adgen: stages of ${ARG_DEFINITIONS} -> ${ARG_HEADER}"
                      INCLUDE_DIRS ${ARG_INCLUDE_DIRS} LIBS ${ARG_LIBS} DEFINES ${ARG_DEFINES})
endfunction()
