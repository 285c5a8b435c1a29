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
# time (a cross build reads the header from the host build: ARBOR_HOST_BUILD_DIR).
include_guard(GLOBAL)

function(arbor_add_stage_ad target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "HEADER;INCLUDE"
                        "DEFINITIONS;INCLUDE_DIRS;LIBS;DEFINES")
  if(ARG_UNPARSED_ARGUMENTS OR NOT ARG_HEADER OR NOT ARG_INCLUDE OR NOT ARG_DEFINITIONS)
    message(FATAL_ERROR "arbor_add_stage_ad(${target} HEADER <h> INCLUDE <h> DEFINITIONS <d...> "
                        "[INCLUDE_DIRS <d...>] [LIBS <t...>] [DEFINES <d...>])")
  endif()
  set(gen_dir ${CMAKE_CURRENT_FUNCTION_LIST_DIR})
  string(REPLACE ";" ", " def_list "${ARG_DEFINITIONS}")
  set(def_names "")
  foreach(d IN LISTS ARG_DEFINITIONS)
    if(def_names)
      string(APPEND def_names ", ")
    endif()
    string(APPEND def_names "\"${d}\"")
  endforeach()
  set(stage_include ${ARG_INCLUDE})
  set(src ${CMAKE_CURRENT_BINARY_DIR}/${target}_adgen.cpp)
  configure_file(${gen_dir}/adgen_stage.cpp.in ${src} @ONLY)
  add_executable(${target}_adgen EXCLUDE_FROM_ALL ${src})
  target_include_directories(${target}_adgen PRIVATE ${gen_dir} ${ARG_INCLUDE_DIRS})
  target_link_libraries(${target}_adgen PRIVATE arbor::arbor ${ARG_LIBS})
  target_compile_definitions(${target}_adgen PRIVATE ${ARG_DEFINES})
  target_compile_options(${target}_adgen PRIVATE -O1)
  set(dir ${CMAKE_CURRENT_BINARY_DIR}/${target}_gen)
  set(out ${dir}/${ARG_HEADER})
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}
    COMMAND ${target}_adgen ${out}
    DEPENDS ${target}_adgen
    COMMENT "arbor-adgen: stages of ${ARG_DEFINITIONS} -> ${ARG_HEADER}"
    VERBATIM)
  add_custom_target(${target}_generate DEPENDS ${out})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_generate)
  target_include_directories(${target} INTERFACE $<BUILD_INTERFACE:${dir}> ${ARG_INCLUDE_DIRS})
  target_link_libraries(${target} INTERFACE ${ARG_LIBS})
  target_compile_definitions(${target} INTERFACE ${ARG_DEFINES})
endfunction()
