# arbor_add_function_ad(<target> HEADER <name.hpp> INCLUDE <header> FUNCTIONS <qualified names...>
#                       [INCLUDE_DIRS <dirs...>] [LIBS <targets...>])
#
# Generated straight-line Jacobians of user functions (arbor::ad::UserFunction, see
# arbor/ad/user_function.hpp: nin, nout, nparam and a generic static eval(x, p, y)): builds a
# small host program that includes <header> (found through INCLUDE_DIRS and LIBS' include
# directories), traces each listed function with arbor-adgen's symbolic scalar (gen/ad), takes
# forward or reverse mode, whichever emits fewer operations, and writes <name.hpp> with
# GeneratedFunction specialisations. Creates the INTERFACE library <target> carrying it (it links
# LIBS). Select the code with the provider tag arbor::ad::Generated on call nodes of
# ad::user_function<F>(params). Native builds only: the program runs at build time.
include_guard(GLOBAL)
include(${CMAKE_CURRENT_LIST_DIR}/ArborAdgenProgram.cmake)

function(arbor_add_function_ad target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "HEADER;INCLUDE" "FUNCTIONS;INCLUDE_DIRS;LIBS")
  if(ARG_UNPARSED_ARGUMENTS OR NOT ARG_HEADER OR NOT ARG_INCLUDE OR NOT ARG_FUNCTIONS)
    message(FATAL_ERROR "arbor_add_function_ad(${target} HEADER <h> INCLUDE <h> FUNCTIONS <f...> "
                        "[INCLUDE_DIRS <d...>] [LIBS <t...>])")
  endif()
  string(REPLACE ";" ", " fn_list "${ARG_FUNCTIONS}")
  _arbor_adgen_quoted(fn_names ${ARG_FUNCTIONS})
  set(fn_include ${ARG_INCLUDE})
  set(src ${CMAKE_CURRENT_BINARY_DIR}/${target}_adgen.cpp)
  configure_file(${CMAKE_CURRENT_FUNCTION_LIST_DIR}/adgen_function.cpp.in ${src} @ONLY)
  _arbor_adgen_header(${target} SOURCE ${src} HEADER ${ARG_HEADER}
                      COMMENT "arbor-adgen: ${ARG_FUNCTIONS} -> ${ARG_HEADER}"
                      INCLUDE_DIRS ${ARG_INCLUDE_DIRS} LIBS ${ARG_LIBS})
endfunction()
