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

function(arbor_add_function_ad target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "HEADER;INCLUDE" "FUNCTIONS;INCLUDE_DIRS;LIBS")
  if(ARG_UNPARSED_ARGUMENTS OR NOT ARG_HEADER OR NOT ARG_INCLUDE OR NOT ARG_FUNCTIONS)
    message(FATAL_ERROR "arbor_add_function_ad(${target} HEADER <h> INCLUDE <h> FUNCTIONS <f...> "
                        "[INCLUDE_DIRS <d...>] [LIBS <t...>])")
  endif()
  set(gen_dir ${CMAKE_CURRENT_FUNCTION_LIST_DIR})
  string(REPLACE ";" ", " fn_list "${ARG_FUNCTIONS}")
  set(fn_names "")
  foreach(f IN LISTS ARG_FUNCTIONS)
    if(fn_names)
      string(APPEND fn_names ", ")
    endif()
    string(APPEND fn_names "\"${f}\"")
  endforeach()
  set(fn_include ${ARG_INCLUDE})
  set(src ${CMAKE_CURRENT_BINARY_DIR}/${target}_adgen.cpp)
  configure_file(${gen_dir}/adgen_function.cpp.in ${src} @ONLY)
  add_executable(${target}_adgen EXCLUDE_FROM_ALL ${src})
  target_include_directories(${target}_adgen PRIVATE ${gen_dir} ${ARG_INCLUDE_DIRS})
  target_link_libraries(${target}_adgen PRIVATE arbor::arbor ${ARG_LIBS})
  target_compile_options(${target}_adgen PRIVATE -O1)
  set(dir ${CMAKE_CURRENT_BINARY_DIR}/${target}_gen)
  set(out ${dir}/${ARG_HEADER})
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}
    COMMAND ${target}_adgen ${out}
    DEPENDS ${target}_adgen
    COMMENT "arbor-adgen: ${ARG_FUNCTIONS} -> ${ARG_HEADER}"
    VERBATIM)
  add_custom_target(${target}_generate DEPENDS ${out})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_generate)
  target_include_directories(${target} INTERFACE $<BUILD_INTERFACE:${dir}> ${ARG_INCLUDE_DIRS})
  target_link_libraries(${target} INTERFACE ${ARG_LIBS})
endfunction()
