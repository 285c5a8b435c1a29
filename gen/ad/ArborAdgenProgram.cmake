# Shared by arbor_add_function_ad and arbor_add_stage_ad (gen/ad): the host program that writes a
# generated header at build time, the rule that runs it and the INTERFACE library carrying the
# header.
include_guard(GLOBAL)

# _arbor_adgen_quoted(<out> <items...>): "a", "b", ... (a C++ initializer list of the names).
function(_arbor_adgen_quoted out)
  set(s "")
  foreach(item IN LISTS ARGN)
    if(s)
      string(APPEND s ", ")
    endif()
    string(APPEND s "\"${item}\"")
  endforeach()
  set(${out} "${s}" PARENT_SCOPE)
endfunction()

# _arbor_adgen_header(<target> SOURCE <program.cpp> HEADER <name.hpp> COMMENT <text>
#                     [INCLUDE_DIRS <dirs...>] [LIBS <targets...>] [DEFINES <definitions...>])
# Builds <target>_adgen from SOURCE (-O1, gen/ad on its include path), runs it to write
# <binary dir>/<target>_gen/<HEADER>, and creates the INTERFACE library <target> (the header's
# folder and INCLUDE_DIRS on its include path; it links LIBS and defines DEFINES).
function(_arbor_adgen_header target)
  cmake_parse_arguments(PARSE_ARGV 1 ARG "" "SOURCE;HEADER;COMMENT" "INCLUDE_DIRS;LIBS;DEFINES")
  add_executable(${target}_adgen EXCLUDE_FROM_ALL ${ARG_SOURCE})
  target_include_directories(${target}_adgen PRIVATE ${CMAKE_CURRENT_FUNCTION_LIST_DIR}
                                                     ${ARG_INCLUDE_DIRS})
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
    COMMENT "${ARG_COMMENT}"
    VERBATIM)
  add_custom_target(${target}_generate DEPENDS ${out})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_generate)
  target_include_directories(${target} INTERFACE $<BUILD_INTERFACE:${dir}> ${ARG_INCLUDE_DIRS})
  target_link_libraries(${target} INTERFACE ${ARG_LIBS})
  target_compile_definitions(${target} INTERFACE ${ARG_DEFINES})
endfunction()
